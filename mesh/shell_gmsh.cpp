#include "mesh/shell_gmsh.hpp"

#include <gmsh.h>

#include <unordered_map>

#include "kernels/error.hpp"
#include "mesh/gmsh_model.hpp"

namespace shatter {

ShellMesh mesh_shell_shape(const ShellShapeSpec& s, const std::string& where) {
  GmshSession session;
  gmsh::model::add("shell");
  const Vec3& c = s.center;
  if (s.shape == "sphere") {
    gmsh::model::occ::addSphere(c.x(), c.y(), c.z(), s.radius);
  } else if (s.shape == "disk") {
    gmsh::model::occ::addDisk(c.x(), c.y(), c.z(), s.radius, s.radius);
  } else if (s.shape == "rectangle") {
    gmsh::model::occ::addRectangle(c.x() - 0.5 * s.width, c.y() - 0.5 * s.height, c.z(), s.width, s.height);
  } else if (s.shape == "cylinder") {
    const Vec3 d = s.length * s.axis.normalized();
    const Vec3 base = c - 0.5 * d;
    gmsh::model::occ::addCylinder(base.x(), base.y(), base.z(), d.x(), d.y(), d.z(), s.radius);
  } else {
    throw InputError(where + ".shape: expected one of sphere, disk, rectangle, cylinder; got '" + s.shape + "'");
  }
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMin", s.element_size);
  gmsh::option::setNumber("Mesh.MeshSizeMax", s.element_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  if (s.shape == "rectangle") {
    // Structured (docs/shells.md "The control mesh"): every boundary vertex
    // has the 3 triangles of the regular lattice (1 or 2 at the corners), so
    // that ghost vertices complete every boundary patch; all diagonals alike,
    // so that every interior vertex has valence 6.
    transfinite_curves(s.element_size);
    gmsh::vectorpair faces;
    gmsh::model::getEntities(faces, 2);
    for (const auto& [dim, tag] : faces) gmsh::model::mesh::setTransfiniteSurface(tag, "Left");
  }
  gmsh::model::mesh::generate(2);
  // The surfaces that make the mid-surface: all of them, except a cylinder's
  // two flat caps.
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  std::vector<Vec3> points;
  std::vector<std::array<Index, 3>> triangles;
  std::unordered_map<std::size_t, Index> local;
  for (const auto& [dim, tag] : surfaces) {
    std::string type;
    gmsh::model::getType(dim, tag, type);
    if (s.shape == "cylinder" && type == "Plane") continue;
    std::vector<std::size_t> elem_tags, node_tags;
    gmsh::model::mesh::getElementsByType(2, elem_tags, node_tags, tag);
    for (std::size_t i = 0; i < node_tags.size(); i += 3) {
      std::array<Index, 3> t;
      for (int k = 0; k < 3; ++k) {
        const auto [it, inserted] = local.try_emplace(node_tags[i + k], static_cast<Index>(points.size()));
        if (inserted) {
          std::vector<double> coord, param;
          gmsh::model::mesh::getNode(node_tags[i + k], coord, param);
          points.emplace_back(coord[0], coord[1], coord[2]);
        }
        t[k] = it->second;
      }
      triangles.push_back(t);
    }
  }
  if (triangles.empty()) throw InputError(where + ": Gmsh made no triangles of the " + s.shape);
  return build_shell_mesh(std::move(points), std::move(triangles), where);
}

}  // namespace shatter
