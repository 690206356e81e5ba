#include "mesh/gmsh_model.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

#include "kernels/error.hpp"

namespace shatter {
namespace {

std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

bool& gmsh_initialized() {
  static bool initialized = false;
  return initialized;
}

/// The family of a Gmsh volume element type (singular and plural), by the
/// Gmsh reference manual's MSH list (asking Gmsh, getElementProperties,
/// builds a nodal basis that Gmsh 4.8 frees wrongly for prisms:
/// tests/fuzz/README.md); null for other types.
struct VolumeFamily {
  const char* one;
  const char* many;
};

const VolumeFamily* volume_family(int type) {
  static constexpr VolumeFamily tet{"tetrahedron", "tetrahedra"}, hex{"hexahedron", "hexahedra"},
      prism{"prism", "prisms"}, pyramid{"pyramid", "pyramids"};
  switch (type) {
    case 4:
    case 11:
    case 29:
    case 30:
    case 31:
      return &tet;
    case 5:
    case 12:
    case 17:
    case 92:
    case 93:
      return &hex;
    case 6:
    case 13:
    case 18:
      return &prism;
    case 7:
    case 14:
    case 19:
      return &pyramid;
    default:
      return nullptr;
  }
}

/// "physical volume 'a'", "physical volumes 'a', 'b'" or "no physical
/// volume": the physical volumes that hold `volumes` (named, or by tag).
std::string physical_volumes_of(const std::set<int>& volumes) {
  std::set<std::string> names;
  for (int v : volumes) {
    std::vector<int> tags;
    gmsh::model::getPhysicalGroupsForEntity(3, v, tags);
    for (int t : tags) {
      std::string name;
      gmsh::model::getPhysicalName(3, t, name);
      names.insert(name.empty() ? std::to_string(t).insert(0, 1, '#') : "'" + name + "'");
    }
  }
  if (names.empty()) return "in no physical volume";
  std::string out = names.size() == 1 ? "physical volume" : "physical volumes";
  const char* separator = " ";
  for (const std::string& name : names) {
    out += separator;
    out += name;
    separator = ", ";
  }
  return out;
}

}  // namespace

GmshSession::GmshSession() : lock_(gmsh_mutex()) {
  if (!gmsh_initialized()) gmsh::initialize(0, nullptr, false);
  gmsh_initialized() = true;
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 1);
  gmsh::option::setNumber("General.NumThreads", 1);  // reproducible meshes
  gmsh::clear();
}

GmshSession::~GmshSession() {
  std::string gmsh_error;
  gmsh::logger::getLastError(gmsh_error);
  if (!gmsh_error.empty()) {
    gmsh::finalize();
    gmsh_initialized() = false;
  } else {
    gmsh::clear();
  }
}

void open_in_gmsh(const std::string& path, const std::string& format, const std::string& where,
                  const std::string& copy_of) {
  try {
    gmsh::open(path);
  } catch (...) {  // Gmsh 4.8 throws a bare value; its log holds the reason
    std::string last;
    gmsh::logger::getLastError(last);
    const std::string what = copy_of.empty() ? "'" + path + "' as " + format + " file"
                                             : "its .msh copy of '" + copy_of + "' (a file it read but wrote unreadably)";
    throw InputError(where + ": Gmsh cannot read " + what + (last.empty() ? "" : ": " + last));
  }
}

std::vector<int> selected_volumes(const std::string& physical, const std::string& where) {
  std::vector<int> volumes;
  if (physical.empty()) {
    gmsh::vectorpair all;
    gmsh::model::getEntities(all, 3);
    for (const auto& [dim, tag] : all) volumes.push_back(tag);
    return volumes;
  }
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 3);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    if (name == physical) {
      std::vector<int> ents;
      gmsh::model::getEntitiesForPhysicalGroup(dim, tag, ents);
      volumes.insert(volumes.end(), ents.begin(), ents.end());
    }
  }
  if (volumes.empty()) throw InputError(where + ": no physical volume named '" + physical + "' in the mesh file");
  return volumes;
}

void require_tetrahedra_only(const std::vector<int>& volumes, const std::string& path, const std::string& physical,
                             const std::string& where) {
  struct Kind {
    std::string one, many;
    std::size_t count = 0;
    std::set<int> volumes;
  };
  std::map<std::string, Kind> kinds;  // by plural name
  bool others = false;
  for (int v : volumes) {
    std::vector<int> types;
    gmsh::model::mesh::getElementTypes(types, 3, v);
    for (int type : types) {
      std::vector<std::size_t> tags, nodes;
      gmsh::model::mesh::preallocateElementsByType(type, true, false, tags, nodes, v);
      const VolumeFamily* family = volume_family(type);
      const std::string other = "element of Gmsh type " + std::to_string(type);
      const std::string many = family ? family->many : "elements of Gmsh type " + std::to_string(type);
      Kind& k = kinds.try_emplace(many, Kind{family ? family->one : other, many, 0, {}}).first->second;
      k.count += tags.size();
      k.volumes.insert(v);
      others = others || many != "tetrahedra";
    }
  }
  if (!others) return;
  // Tetrahedra first, then the others by name.
  std::string held;
  auto add = [&](const Kind& k) {
    if (!held.empty()) held += ", ";
    held +=
        std::to_string(k.count) + " " + (k.count == 1 ? k.one : k.many) + " (" + physical_volumes_of(k.volumes) + ")";
  };
  if (auto t = kinds.find("tetrahedra"); t != kinds.end()) add(t->second);
  for (const auto& [name, k] : kinds)
    if (name != "tetrahedra") add(k);
  throw InputError(where + ": " + (physical.empty() ? "" : "physical volume '" + physical + "' of ") + "'" + path +
                   "' holds " + held +
                   "; expected tetrahedra only: name a physical volume of tetrahedra only with mesh.physical, or "
                   "mesh the body with tetrahedra");
}

Mesh model_tetrahedra(const std::vector<int>& volumes, int order, int body, int material, const std::string& where) {
  const int type = order == 1 ? 4 : 11;
  const int npe = order == 1 ? 4 : 10;
  Mesh mesh;
  mesh.order = order;
  std::unordered_map<std::size_t, Index> local;
  std::vector<std::size_t> node_tags_all;
  for (int v : volumes) {
    std::vector<std::size_t> elem_tags, node_tags;
    gmsh::model::mesh::getElementsByType(type, elem_tags, node_tags, v);
    for (std::size_t i = 0; i < node_tags.size(); ++i) {
      auto [it, inserted] = local.try_emplace(node_tags[i], static_cast<Index>(local.size()));
      if (inserted) node_tags_all.push_back(node_tags[i]);
      mesh.conn.push_back(it->second);
    }
    for (std::size_t t : elem_tags) mesh.elem_gid.push_back(static_cast<GlobalId>(t));
  }
  if (mesh.elem_gid.empty()) {
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(order == 1 ? 11 : 4, et, nt);
    throw InputError(
        where + ": no " + std::to_string(npe) + "-node tetrahedra in the mesh" +
        (et.empty() ? "" : " (it has " + std::to_string(npe == 4 ? 10 : 4) + "-node ones: set mesh.order to match)"));
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

std::vector<PhysicalGroup> model_physical_groups() {
  std::vector<PhysicalGroup> out;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    PhysicalGroup g;
    g.dim = dim;
    gmsh::model::getPhysicalName(dim, tag, g.name);
    if (g.name.empty()) continue;
    std::vector<std::size_t> nodes;
    std::vector<double> coords;
    gmsh::model::mesh::getNodesForPhysicalGroup(dim, tag, nodes, coords);
    g.nodes.assign(nodes.begin(), nodes.end());
    if (dim == 2) {
      std::vector<int> entities;
      gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
      for (int entity : entities)
        for (const int type : {2, 9}) {  // 3- and 6-node triangles: corners first
          std::vector<std::size_t> elements, element_nodes;
          gmsh::model::mesh::getElementsByType(type, elements, element_nodes, entity);
          const std::size_t k = type == 2 ? 3 : 6;
          for (std::size_t t = 0; t + k <= element_nodes.size(); t += k)
            g.triangles.push_back({static_cast<GlobalId>(element_nodes[t]), static_cast<GlobalId>(element_nodes[t + 1]),
                                   static_cast<GlobalId>(element_nodes[t + 2])});
        }
    }
    out.push_back(std::move(g));
  }
  return out;
}

void transfinite_curves(double size) {
  gmsh::vectorpair curves;
  gmsh::model::getEntities(curves, 1);
  for (const auto& [dim, tag] : curves) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    const double length = std::max({x1 - x0, y1 - y0, z1 - z0});
    gmsh::model::mesh::setTransfiniteCurve(tag, std::max(2, static_cast<int>(std::lround(length / size)) + 1));
  }
}

}  // namespace shatter
