#include "runtime/regions.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <set>
#include <unordered_map>

#include "kernels/error.hpp"
#include "mesh/topology.hpp"

namespace shatter {
namespace {

/// A named face of a shape: a surface test of a point and the outward normal
/// a face on it must have (within 84 degrees, cos > 0.1: a chord of a coarse
/// curved surface leans by up to 60 degrees, a face of the neighbouring
/// surface, e.g. a cylinder's top triangle with its corners on the rim, is
/// at 90).
struct NamedFace {
  std::function<bool(const Vec3&)> on;         ///< the point lies on the surface
  std::function<Vec3(const Vec3&)> normal;     ///< the surface's outward normal at a point
};

std::vector<NamedFace> named_face(const ShapeSpec& s, const std::string& name) {
  const double tol = 1e-3 * s.element_size;
  const Vec3 c = s.center;
  std::vector<NamedFace> out;
  if (s.shape == "box") {
    const Vec3 half = 0.5 * s.size;
    for (int k = 0; k < 3; ++k)
      for (int side = 0; side < 2; ++side) {
        const std::string n = std::string(1, "xyz"[k]) + (side ? "max" : "min");
        if (n != name) continue;
        const double sign = side ? 1.0 : -1.0;
        out.push_back({[=](const Vec3& X) { return sign * (X[k] - c[k]) >= half[k] - tol; },
                       [=](const Vec3&) { return Vec3(sign * Vec3::Unit(k)); }});
      }
    return out;
  }
  const Vec3 a = s.axis.normalized();
  auto axial = [=](const Vec3& X) { return (X - c).dot(a); };
  auto radial = [=](const Vec3& X) {
    const Vec3 d = X - c;
    return Vec3(d - d.dot(a) * a);
  };
  auto centred = [=](const Vec3& X) { return Vec3(X - c); };
  const double half_length = 0.5 * s.length;
  auto end = [&](double sign) {
    out.push_back({[=](const Vec3& X) { return sign * axial(X) >= half_length - tol; },
                   [=](const Vec3&) { return Vec3(sign * a); }});
  };
  auto round = [&](double r, double sign, auto direction) {
    out.push_back({[=](const Vec3& X) { return std::abs(direction(X).norm() - r) <= tol; },
                   [=](const Vec3& X) { return Vec3(sign * direction(X).normalized()); }});
  };
  if (s.shape == "cylinder" || s.shape == "tube") {
    const bool tube = s.shape == "tube";
    if (name == "top") end(1.0);
    if (name == "bottom") end(-1.0);
    if (name == "side" || name == "outer") round(tube ? s.outer_radius : s.radius, 1.0, radial);
    if (tube && (name == "side" || name == "inner")) round(s.inner_radius, -1.0, radial);
  } else if (s.shape == "sphere") {
    if (name == "surface") round(s.radius, 1.0, centred);
    if (name == "inner" && s.inner_radius > 0) round(s.inner_radius, -1.0, centred);
  }
  return out;
}

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// The physical groups named `name`; InputError listing the names when none is.
std::vector<const PhysicalGroup*> groups_named(const RegionContext& c, const std::string& name) {
  std::vector<const PhysicalGroup*> out;
  std::set<std::string> names;
  for (const PhysicalGroup& g : *c.groups) {
    names.insert(g.name);
    if (g.name == name) out.push_back(&g);
  }
  if (out.empty())
    throw InputError(c.where + ": the mesh file of body '" + c.body_name + "' has no physical group named '" + name +
                     "'; expected one of its named physical groups (" +
                     (names.empty() ? "it has none" : list({names.begin(), names.end()})) + ")");
  return out;
}

/// The body's nodes by their ids (node_gid).
std::unordered_map<GlobalId, Index> nodes_by_gid(const RegionContext& c) {
  std::unordered_map<GlobalId, Index> out;
  for (Index i = 0; i < c.mesh.num_nodes(); ++i)
    if (c.mesh.node_body[i] == c.body) out.emplace(c.mesh.node_gid[i], i);
  return out;
}

/// The scene reader lets a physical group name only a mesh-file body's, a face only a shape's.
void require_selector(const RegionContext& c, const RegionSpec& r) {
  SHATTER_REQUIRE((r.kind != RegionSpec::Kind::physical || c.groups) && (r.kind != RegionSpec::Kind::face || c.shape),
                  c.where << ": a physical group needs a mesh-file body, a named face a shape");
}

std::string describe(const RegionSpec& r) {
  switch (r.kind) {
    case RegionSpec::Kind::box:
      return "the box";
    case RegionSpec::Kind::physical:
      return "the physical group '" + r.name + "'";
    case RegionSpec::Kind::face:
      return "the face '" + r.name + "'";
  }
  return "";
}

}  // namespace

std::vector<std::string> shape_face_names(const ShapeSpec& shape) {
  if (shape.shape == "box") return {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  if (shape.shape == "cylinder") return {"top", "bottom", "side"};
  if (shape.shape == "tube") return {"top", "bottom", "side", "inner", "outer"};
  if (shape.shape == "sphere" && shape.inner_radius > 0) return {"surface", "inner"};
  if (shape.shape == "sphere") return {"surface"};
  return {};
}

std::vector<BoundaryFace> region_faces(const RegionContext& c, const RegionSpec& r) {
  require_selector(c, r);
  const Mesh& mesh = c.mesh;
  const Topology topo = build_topology(mesh);
  std::vector<BoundaryFace> out;
  std::vector<NamedFace> named;
  if (r.kind == RegionSpec::Kind::face) named = named_face(*c.shape, r.name);
  std::set<std::array<GlobalId, 3>> triangles;
  if (r.kind == RegionSpec::Kind::physical) {
    bool surface = false;
    for (const PhysicalGroup* g : groups_named(c, r.name)) {
      surface = surface || g->dim == 2;
      for (std::array<GlobalId, 3> t : g->triangles) {
        std::sort(t.begin(), t.end());
        triangles.insert(t);
      }
    }
    if (!surface)
      throw InputError(c.where + ".physical: the physical group '" + r.name + "' of body '" + c.body_name +
                       "' is not a surface; expected a physical surface (a load acts on faces)");
  }
  for (Index f = 0; f < topo.num_facets(); ++f) {
    if (topo.is_interior(f)) continue;
    const Index e = topo.facet_elem[f][0];
    if (mesh.elem_body[e] != c.body) continue;
    const int face = topo.facet_face[f][0];
    const Index* n = mesh.element(e);
    const auto& local = kTetFaces[face];
    const Vec3 X[3] = {mesh.reference[n[local[0]]], mesh.reference[n[local[1]]], mesh.reference[n[local[2]]]};
    bool hit = false;
    switch (r.kind) {
      case RegionSpec::Kind::box:
        hit = r.box_holds(X[0]) && r.box_holds(X[1]) && r.box_holds(X[2]);
        break;
      case RegionSpec::Kind::physical: {
        std::array<GlobalId, 3> t = {mesh.node_gid[n[local[0]]], mesh.node_gid[n[local[1]]], mesh.node_gid[n[local[2]]]};
        std::sort(t.begin(), t.end());
        hit = triangles.count(t) > 0;
        break;
      }
      case RegionSpec::Kind::face: {
        const Vec3 normal = (X[1] - X[0]).cross(X[2] - X[0]).normalized();
        const Vec3 centre = (X[0] + X[1] + X[2]) / 3.0;
        for (const NamedFace& s : named)
          hit = hit || (s.on(X[0]) && s.on(X[1]) && s.on(X[2]) && normal.dot(s.normal(centre)) > 0.1);
        break;
      }
    }
    if (hit) out.push_back({e, face});
  }
  std::sort(out.begin(), out.end(),
            [](const BoundaryFace& a, const BoundaryFace& b) { return std::pair(a.element, a.face) < std::pair(b.element, b.face); });
  if (out.empty())
    throw InputError(c.where + ": " + describe(r) + " holds no boundary face of body '" + c.body_name +
                     "'; expected a region on the body's surface");
  return out;
}

std::vector<Index> region_nodes(const RegionContext& c, const RegionSpec& r) {
  require_selector(c, r);
  const Mesh& mesh = c.mesh;
  std::vector<Index> out;
  if (r.kind == RegionSpec::Kind::box) {
    for (Index i = 0; i < mesh.num_nodes(); ++i)
      if (mesh.node_body[i] == c.body && r.box_holds(mesh.reference[i])) out.push_back(i);
    if (out.empty())
      throw InputError(c.where + ": the box holds no node of body '" + c.body_name +
                       "'; expected a box around some of its nodes");
    return out;
  }
  if (r.kind == RegionSpec::Kind::physical) {
    const auto by_gid = nodes_by_gid(c);
    for (const PhysicalGroup* g : groups_named(c, r.name))
      for (GlobalId id : g->nodes)
        if (const auto it = by_gid.find(id); it != by_gid.end()) out.push_back(it->second);
  } else {
    const int k = mesh.order == 1 ? 3 : 6;
    for (const BoundaryFace& f : region_faces(c, r))
      for (int a = 0; a < k; ++a) out.push_back(mesh.element(f.element)[kTetFaces[f.face][a]]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.empty())
    throw InputError(c.where + ": " + describe(r) + " holds no node of body '" + c.body_name +
                     "'; expected a group of nodes of the body's mesh");
  return out;
}

}  // namespace shatter
