#include "mesh/gmsh_input.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <unordered_map>

#include "kernels/error.hpp"

namespace shatter {
namespace {

// The Gmsh API is one global model: serialise every use of it.
std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

struct GmshSession {
  GmshSession() {
    static bool initialized = false;
    if (!initialized) gmsh::initialize(0, nullptr, false);
    initialized = true;
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    gmsh::option::setNumber("General.NumThreads", 1);  // reproducible meshes
    gmsh::clear();
  }
  ~GmshSession() { gmsh::clear(); }
};

// Collect the tetrahedra of the current Gmsh model (optionally one physical
// volume) into a Mesh, renumbering nodes densely in order of first use.
Mesh extract_tets(int order, int body, int material, const std::string& physical,
                  const std::string& where) {
  const int type = order == 1 ? 4 : 11;
  const int npe = order == 1 ? 4 : 10;
  std::vector<int> entities;
  if (!physical.empty()) {
    gmsh::vectorpair groups;
    gmsh::model::getPhysicalGroups(groups, 3);
    for (const auto& [dim, tag] : groups) {
      std::string name;
      gmsh::model::getPhysicalName(dim, tag, name);
      if (name == physical) {
        std::vector<int> ents;
        gmsh::model::getEntitiesForPhysicalGroup(dim, tag, ents);
        entities.insert(entities.end(), ents.begin(), ents.end());
      }
    }
    if (entities.empty())
      throw InputError(where + ": no physical volume named '" + physical + "' in the mesh file");
  } else {
    entities.push_back(-1);
  }
  Mesh mesh;
  mesh.order = order;
  std::unordered_map<std::size_t, Index> local;
  std::vector<std::size_t> node_tags_all;
  for (int ent : entities) {
    std::vector<std::size_t> elem_tags, node_tags;
    gmsh::model::mesh::getElementsByType(type, elem_tags, node_tags, ent);
    for (std::size_t i = 0; i < node_tags.size(); ++i) {
      auto [it, inserted] = local.try_emplace(node_tags[i], static_cast<Index>(local.size()));
      if (inserted) node_tags_all.push_back(node_tags[i]);
      mesh.conn.push_back(it->second);
    }
    for (std::size_t t : elem_tags) mesh.elem_gid.push_back(static_cast<GlobalId>(t));
  }
  if (mesh.elem_gid.empty()) {
    int other = 0;
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(order == 1 ? 11 : 4, et, nt);
    other = static_cast<int>(et.size());
    throw InputError(where + ": no " + std::to_string(npe) + "-node tetrahedra in the mesh" +
                     (other ? " (it has " + std::to_string(npe == 4 ? 10 : 4) +
                                  "-node ones: set mesh.order to match)"
                            : ""));
  }
  mesh.reference.resize(node_tags_all.size());
  for (std::size_t i = 0; i < node_tags_all.size(); ++i) {
    std::vector<double> coord, param;
    gmsh::model::mesh::getNode(node_tags_all[i], coord, param);
    mesh.reference[i] = Vec3(coord[0], coord[1], coord[2]);
  }
  mesh.node_gid.assign(node_tags_all.begin(), node_tags_all.end());
  mesh.node_body.assign(mesh.reference.size(), body);
  mesh.elem_body.assign(mesh.elem_gid.size(), body);
  mesh.elem_material.assign(mesh.elem_gid.size(), material);
  mesh.build_node_elements();
  return mesh;
}

}  // namespace

Mesh mesh_shape(const ShapeSpec& s, int body, int material, const std::string& where) {
  std::lock_guard lock(gmsh_mutex());
  GmshSession session;
  gmsh::model::add("shape");
  const Vec3 axis = s.axis.normalized();
  // Volume `outer` minus volume `inner` (OCC boolean): notched boxes, tubes, hollow
  // spheres. Returns the resulting volumes.
  auto cut = [](int outer, int inner) {
    gmsh::vectorpair out;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, out, map);
    return out;
  };
  if (s.shape == "box") {
    const Vec3 lo = s.center - 0.5 * s.size;
    const int box = gmsh::model::occ::addBox(lo.x(), lo.y(), lo.z(), s.size.x(), s.size.y(), s.size.z());
    if (s.notch_size.squaredNorm() > 0) {
      const Vec3 nlo = s.notch_center - 0.5 * s.notch_size;
      const int notch = gmsh::model::occ::addBox(nlo.x(), nlo.y(), nlo.z(), s.notch_size.x(), s.notch_size.y(),
                                                 s.notch_size.z());
      const gmsh::vectorpair out = cut(box, notch);
      const double volume = s.size.prod();
      double mass = 0;
      if (out.size() == 1) gmsh::model::occ::getMass(3, out[0].second, mass);
      if (out.size() != 1 || !(mass < volume * (1 - 1e-12)))
        throw InputError(where + ".notch: expected a box that cuts into the body and leaves it in one piece");
    }
  } else if (s.shape == "cylinder") {
    const Vec3 base = s.center - 0.5 * s.length * axis;
    const Vec3 d = s.length * axis;
    gmsh::model::occ::addCylinder(base.x(), base.y(), base.z(), d.x(), d.y(), d.z(), s.radius);
  } else if (s.shape == "sphere") {
    const int outer = gmsh::model::occ::addSphere(s.center.x(), s.center.y(), s.center.z(), s.radius);
    if (s.inner_radius > 0)
      cut(outer, gmsh::model::occ::addSphere(s.center.x(), s.center.y(), s.center.z(), s.inner_radius));
  } else if (s.shape == "tube") {
    const Vec3 base = s.center - 0.5 * s.length * axis;
    const Vec3 d = s.length * axis;
    const int outer = gmsh::model::occ::addCylinder(base.x(), base.y(), base.z(), d.x(), d.y(), d.z(),
                                                    s.outer_radius);
    cut(outer, gmsh::model::occ::addCylinder(base.x(), base.y(), base.z(), d.x(), d.y(), d.z(), s.inner_radius));
  } else {
    throw InputError(where + ".shape: expected one of box, cylinder, sphere, tube; got '" + s.shape + "'");
  }
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMin", s.element_size);
  gmsh::option::setNumber("Mesh.MeshSizeMax", s.element_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 1);
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay
  gmsh::option::setNumber("Mesh.ElementOrder", s.order);
  gmsh::option::setNumber("Mesh.HighOrderOptimize", s.order == 2 ? 1 : 0);
  gmsh::model::mesh::generate(3);
  return extract_tets(s.order, body, material, "", where);
}

Mesh read_msh(const std::string& path, const std::string& physical, int body, int material,
              const std::string& where) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(where + ": mesh file '" + path + "' does not exist or is not a file");
  // Which tetrahedra the file holds, from our own scan: Gmsh 4.8 lists a
  // volume's tets by the type of its first one, overrunning its buffers when
  // the volume holds two orders (docs/errors.md), so such a file never
  // reaches Gmsh.
  std::vector<MshElementType> tets = scan_msh_elements(path, where);
  std::erase_if(tets, [](const MshElementType& t) { return !t.tetrahedron; });
  if (tets.empty())
    throw InputError(where + ": '" + path + "' holds no tetrahedra (expected 4- or 10-node tets)");
  if (tets.size() > 1)
    throw InputError(where + ": '" + path + "' mixes " + std::to_string(tets[0].nodes) + "- and " +
                     std::to_string(tets[1].nodes) + "-node tetrahedra (elements " +
                     std::to_string(tets[0].first_tag) + " and " +
                     std::to_string(tets[1].first_tag) +
                     "); expected tetrahedra of one order, 4- or 10-node");
  if (tets[0].type != 4 && tets[0].type != 11)
    throw InputError(where + ": '" + path + "' holds " + std::to_string(tets[0].nodes) +
                     "-node tetrahedra; expected 4- or 10-node tets");
  std::lock_guard lock(gmsh_mutex());
  GmshSession session;
  try {
    gmsh::open(path);
  } catch (...) {  // Gmsh 4.8 throws a bare value; its log holds the reason
    std::string last;
    gmsh::logger::getLastError(last);
    throw InputError(where + ": Gmsh cannot read '" + path + "' as a .msh file" +
                     (last.empty() ? "" : ": " + last));
  }
  return extract_tets(tets[0].type == 4 ? 1 : 2, body, material, physical, where);
}

}  // namespace shatter
