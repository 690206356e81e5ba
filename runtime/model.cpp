#include "runtime/model.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <iomanip>
#include <sstream>

#include "kernels/error.hpp"
#include "kernels/tet4.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/reorder.hpp"
#include "mesh/shape_estimate.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/mesh_broadcast.hpp"
#include "runtime/model_part.hpp"
#include "runtime/part_files.hpp"

namespace shatter {

namespace {

/// Before any meshing: every primitive within kMaxCoordinate, and the
/// estimated elements of all of them at most `max_elements`.
void check_estimate(const Scene& scene, double max_elements) {
  double total = 0;
  for (const BodySpec& body : scene.bodies) {
    if (!body.mesh_file.empty()) continue;
    const std::string where = scene.file + ": " + body.key + ".mesh";
    if (body.shell) {
      check_shape_extent(shell_extent(body.shell->shape), where);
      total += estimated_shell_triangles(body.shell->shape);
      if (total <= max_elements) continue;
      std::ostringstream os;
      os << where << ".element_size: about " << std::setprecision(3) << total
         << " elements and shell triangles estimated for the scene so far (a shell: its area over an equilateral "
            "triangle's of edge element_size); expected at most "
         << max_elements << " (--max-elements raises the limit)";
      throw InputError(os.str());
    }
    check_shape_extent(body.shape, where);
    const double n = estimated_elements(body.shape);
    total += n;
    if (total <= max_elements) continue;
    std::ostringstream os;
    os << where << ".element_size: about " << std::setprecision(3) << n << " elements estimated for this body ("
       << kTetsPerCube << " V / h^3, V = " << shape_volume(body.shape) << " m^3, h = " << body.shape.element_size
       << " m), " << total << " for the scene so far; expected at most " << max_elements
       << " (--max-elements raises the limit)";
    throw InputError(os.str());
  }
}

/// Every body meshed (or read) and checked, appended in order, the elements
/// along a space-filling curve; `groups` receives each body's physical groups
/// (mesh files), their node ids shifted as append_mesh shifts the body's.
Mesh mesh_bodies(const Scene& scene, double max_elements, std::vector<std::vector<PhysicalGroup>>& groups,
                 double& seconds) {
  check_estimate(scene, max_elements);
  const auto t0 = std::chrono::steady_clock::now();
  Mesh mesh;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    const std::string where = scene.file + ": " + body.key + ".mesh" +
                              (body.mesh_file.empty() ? "" : " (" + body.mesh_file + ")");
    std::vector<PhysicalGroup>& body_groups = groups.emplace_back();
    if (body.shell) continue;  // add_shell_bodies
    Mesh part = body.mesh_file.empty() ? mesh_shape(body.shape, static_cast<int>(b), body.material, where)
                                       : read_mesh_file(body.mesh_file, body.mesh_physical, static_cast<int>(b),
                                                        body.material, where, &body_groups);
    validate_mesh(part, where);
    const GlobalId shift = mesh.node_gid.empty() ? 0 : *std::max_element(mesh.node_gid.begin(), mesh.node_gid.end());
    for (PhysicalGroup& g : body_groups) {
      for (GlobalId& id : g.nodes) id += shift;
      for (auto& t : g.triangles)
        for (GlobalId& id : t) id += shift;
    }
    if (mesh.num_elements() > 0 && part.order != mesh.order)
      throw InputError(where + ": element order " + std::to_string(part.order) +
                       " differs from the first body's; expected one order for all bodies");
    append_mesh(mesh, part);
  }
  // Elements along a space-filling curve, nodes by first use: the colored
  // element loop needs consecutive elements to share nodes (3x faster than
  // Gmsh's order, and 15 colors instead of 280; docs/performance.md).
  reorder_for_locality(mesh, GlobalIdPolicy::keep);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return mesh;
}

/// The shell bodies of the scene (build_shell_body), their control vertices
/// appended to `mesh` as nodes in no element, after the solids' nodes.
std::vector<ShellBody> add_shell_bodies(const Scene& scene, Mesh& mesh) {
  std::vector<ShellBody> shells;
  if (mesh.node_elem_offsets.empty()) mesh.node_elem_offsets.push_back(0);
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    if (!scene.bodies[b].shell) continue;
    ShellBody& s = shells.emplace_back(
        build_shell_body(scene, static_cast<int>(b), scene.file + ": " + scene.bodies[b].key + ".mesh"));
    s.first_node = mesh.num_nodes();
    GlobalId gid = mesh.node_gid.empty() ? 0 : *std::max_element(mesh.node_gid.begin(), mesh.node_gid.end());
    for (const Vec3& X : s.mesh.reference) {
      mesh.reference.push_back(X);
      mesh.node_gid.push_back(++gid);
      mesh.node_body.push_back(static_cast<int>(b));
      mesh.node_elem_offsets.push_back(mesh.node_elem_offsets.back());
    }
  }
  return shells;
}

/// `f` on rank 0 of `comm`; a failure there is thrown on every rank
/// (InputError stays InputError), so the ranks end together. Collective.
template <class F>
void on_root(MPI_Comm comm, F f) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string error;
  int kind = 0;  // 0 none, 1 Error, 2 InputError
  if (rank == 0) try {
      f();
    } catch (const InputError& e) {
      error = e.what(), kind = 2;
    } catch (const std::exception& e) {
      error = e.what(), kind = 1;
    }
  int head[2] = {kind, static_cast<int>(error.size())};
  MPI_Bcast(head, 2, MPI_INT, 0, comm);
  if (head[0] != 0) {
    error.resize(head[1]);
    MPI_Bcast(error.data(), head[1], MPI_CHAR, 0, comm);
    if (head[0] == 2) throw InputError(error);
    throw Error(error);
  }
}

/// The nodes of each boundary condition and the faces of each load (scene order).
struct RegionSelection {
  std::vector<std::vector<Index>> condition_nodes;
  std::vector<std::vector<BoundaryFace>> load_faces;
};

RegionSelection select_regions(const Scene& scene, const Mesh& mesh,
                               const std::vector<std::vector<PhysicalGroup>>& groups) {
  RegionSelection s;
  auto context = [&](int body, const std::string& key) {
    const BodySpec& b = scene.bodies[body];
    return RegionContext{mesh, body, b.mesh_file.empty() ? &b.shape : nullptr,
                         b.mesh_file.empty() ? nullptr : &groups[body], scene.file + ": " + key + ".region", b.name};
  };
  for (const BoundaryConditionSpec& bc : scene.boundary_conditions)
    s.condition_nodes.push_back(region_nodes(context(bc.body, bc.key), bc.region));
  for (const LoadSpec& load : scene.loads) s.load_faces.push_back(region_faces(context(load.body, load.key), load.region));
  return s;
}

/// Rank 0's selection sent to every rank of `comm` (collective).
void broadcast_selection(RegionSelection& s, const Scene& scene, MPI_Comm comm) {
  s.condition_nodes.resize(scene.boundary_conditions.size());
  s.load_faces.resize(scene.loads.size());
  for (auto& nodes : s.condition_nodes) broadcast_vector(nodes, 0, comm);
  for (auto& faces : s.load_faces) broadcast_vector(faces, 0, comm);
}

/// The constants, masses, initial and boundary conditions and loads of the model on `mesh`.
void complete_model(Model& m, const RegionSelection& selection);

}  // namespace

bool whole_model_on_every_rank(const Scene& scene) { return scene.has_shells(); }

Model build_model(const Scene& scene, MPI_Comm comm, double max_elements, const std::filesystem::path& parts) {
  Model m;
  m.scene = scene;
  for (const auto& ms : scene.materials)
    m.materials.push_back(NeoHookean::from_young_poisson(ms.young, ms.poisson, ms.density));
  int ranks = 1;
  if (comm != MPI_COMM_SELF) MPI_Comm_size(comm, &ranks);
  std::vector<std::vector<PhysicalGroup>> groups;
  RegionSelection selection;
  double mesh_seconds = 0;
  if (!parts.empty()) {
    if (ranks == 1)
      throw InputError("--parts " + parts.string() + ": part files are for runs on several ranks; expected mpirun -np R "
                       "with the R of `shatter partition --ranks R`, or a run without --parts");
    if (whole_model_on_every_rank(scene))
      throw InputError(scene.file + ": shells hold the whole model on every rank (docs/parallel.md \"Shells on "
                       "ranks\"); expected a run without --parts");
    const auto t0 = std::chrono::steady_clock::now();
    read_part_file(m, parts, comm);
    mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } else if (ranks == 1) {
    m.mesh = mesh_bodies(scene, max_elements, groups, mesh_seconds);
    m.shells = add_shell_bodies(scene, m.mesh);
    selection = select_regions(scene, m.mesh, groups);
    complete_model(m, selection);
  } else if (whole_model_on_every_rank(scene)) {
    // Shells still need the whole model on every rank (docs/parallel.md
    // "Shells on ranks"): every rank builds the shells (each one's Gmsh meshes
    // the same mid-surfaces) after the solids' nodes.
    on_root(comm, [&] { m.mesh = mesh_bodies(scene, max_elements, groups, mesh_seconds); });
    broadcast_mesh(m.mesh, 0, comm);
    m.shells = add_shell_bodies(scene, m.mesh);
    on_root(comm, [&] { selection = select_regions(scene, m.mesh, groups); });
    broadcast_selection(selection, scene, comm);
    complete_model(m, selection);
  } else {
    on_root(comm, [&] {
      m.mesh = mesh_bodies(scene, max_elements, groups, mesh_seconds);
      complete_model(m, select_regions(scene, m.mesh, groups));
      check_ranks(m, ranks);
    });
    distribute_parts(m, comm);
  }
  m.mesh_seconds = mesh_seconds;
  return m;
}

namespace {

void complete_model(Model& m, const RegionSelection& selection) {
  const Scene& scene = m.scene;
  const Mesh& mesh = m.mesh;
  const Index ne = mesh.num_elements(), nn = mesh.num_nodes();
  const int k = mesh.nodes_per_element();
  m.element_volume.resize(ne);
  m.element_node_mass.resize(static_cast<size_t>(ne) * k);
  if (mesh.order == 1) m.tet4_Dm_inv.resize(ne);
  else m.tet10_ref.resize(ne);
  for (Index e = 0; e < ne; ++e) {
    const Index* c = mesh.element(e);
    const double rho = m.materials[mesh.elem_material[e]].density;
    if (mesh.order == 1) {
      const Tet4Reference r = tet4_reference(mesh.reference[c[0]], mesh.reference[c[1]], mesh.reference[c[2]],
                                             mesh.reference[c[3]]);
      m.tet4_Dm_inv[e] = r.Dm_inv;
      m.element_volume[e] = r.volume;
      for (int a = 0; a < 4; ++a) m.element_node_mass[e * 4 + a] = 0.25 * rho * r.volume;  // row sum
    } else {
      Tet10Nodes X;
      for (int a = 0; a < 10; ++a) X.col(a) = mesh.reference[c[a]];
      m.tet10_ref[e] = tet10_reference(X);
      m.element_volume[e] = m.tet10_ref[e].volume;
      const auto frac = tet10_hrz_mass_fractions(X);
      for (int a = 0; a < 10; ++a) m.element_node_mass[e * 10 + a] = frac[a] * rho * m.element_volume[e];
    }
  }
  std::vector<Index> all(nn);
  for (Index i = 0; i < nn; ++i) all[i] = i;
  m.mass.assign(nn, 0.0);
  recompute_node_masses(m, all);

  const int nb = static_cast<int>(scene.bodies.size());
  m.body_mass.assign(nb, 0.0);
  m.body_volume.assign(nb, 0.0);
  for (Index e = 0; e < ne; ++e) {
    m.body_volume[mesh.elem_body[e]] += m.element_volume[e];
    m.body_mass[mesh.elem_body[e]] += m.element_volume[e] * m.materials[mesh.elem_material[e]].density;
  }
  for (const ShellBody& s : m.shells) {
    const std::vector<double> mass = shell_vertex_mass(s, m.materials[s.material]);
    for (Index v = 0; v < s.mesh.num_vertices(); ++v) {
      if (!(mass[v] > 0))
        throw InputError(scene.file + ": " + scene.bodies[s.body].key + ".mesh: control vertex " + std::to_string(v) +
                         " of the shell has lumped mass " + std::to_string(mass[v]) + " kg; expected a positive mass");
      m.mass[s.first_node + v] = mass[v];
    }
    m.body_volume[s.body] = s.thickness * s.area;
    m.body_mass[s.body] = m.body_volume[s.body] * m.materials[s.material].density;
  }

  // Initial velocities: translation, rotation about the body's centre of
  // mass, and a velocity gradient about the same centre.
  std::vector<Vec3> centre(nb, Vec3::Zero());
  for (Index i = 0; i < nn; ++i) centre[mesh.node_body[i]] += m.mass[i] * mesh.reference[i];
  for (int b = 0; b < nb; ++b) centre[b] /= m.body_mass[b];
  m.initial_velocity.resize(nn);
  for (Index i = 0; i < nn; ++i) {
    const BodySpec& body = scene.bodies[mesh.node_body[i]];
    const Vec3 r = mesh.reference[i] - centre[mesh.node_body[i]];
    Vec3 v = body.initial_velocity + body.angular_velocity.cross(r);
    if (body.velocity_gradient) v += *body.velocity_gradient * r;
    m.initial_velocity[i] = v;
  }

  m.bc_mask.assign(nn, 0);
  m.bc_velocity.assign(nn, Vec3::Zero());
  m.bc_condition.assign(nn, {-1, -1, -1});
  // Two conditions that prescribe one component of one node contradict each
  // other unless they agree (the same quantity, value and amplitude: regions
  // that overlap where they fix the same corner).
  for (std::size_t k = 0; k < scene.boundary_conditions.size(); ++k) {
    const BoundaryConditionSpec& bc = scene.boundary_conditions[k];
    for (Index i : selection.condition_nodes[k])
      for (int c = 0; c < 3; ++c) {
        if (!bc.value[c]) continue;
        const int first = m.bc_condition[i][c];
        if (first >= 0) {
          const BoundaryConditionSpec& other = scene.boundary_conditions[first];
          if (other.displacement == bc.displacement && m.bc_velocity[i][c] == *bc.value[c] &&
              other.amplitude == bc.amplitude)
            continue;
          const std::string comp = "[" + std::to_string(c) + "]";
          const Vec3& X = mesh.reference[i];
          std::ostringstream os;
          os << scene.file << ": " << bc.key << "." << bc.quantity() << comp << ": prescribes " << *bc.value[c] << " "
             << bc.unit() << " on node " << mesh.node_gid[i] << " of body '" << scene.bodies[bc.body].name << "' at ("
             << X.x() << ", " << X.y() << ", " << X.z() << "), where " << other.key << "." << other.quantity() << comp
             << " prescribes " << m.bc_velocity[i][c] << " " << other.unit()
             << (other.displacement == bc.displacement && m.bc_velocity[i][c] == *bc.value[c]
                     ? " with another amplitude"
                     : "")
             << "; expected one value per component of a node (regions that overlap must agree)";
          throw InputError(os.str());
        }
        m.bc_condition[i][c] = static_cast<std::int32_t>(k);
        m.bc_mask[i] |= static_cast<std::uint8_t>(1u << c);
        m.bc_velocity[i][c] = *bc.value[c];
        m.initial_velocity[i][c] =
            *bc.value[c] * (bc.displacement ? bc.amplitude.rate(0.0) : bc.amplitude.value(0.0));
      }
  }
  m.load_faces.clear();
  for (std::size_t k = 0; k < selection.load_faces.size(); ++k)
    for (const BoundaryFace& f : selection.load_faces[k])
      m.load_faces.push_back({f.element, static_cast<std::int32_t>(f.face), static_cast<std::int32_t>(k)});
}

}  // namespace

void recompute_node_masses(Model& model, const std::vector<Index>& nodes) {
  const Mesh& mesh = model.mesh;
  const int k = mesh.nodes_per_element();
  for (Index i : nodes) {
    double sum = 0;
    for (Index p = mesh.node_elem_offsets[i]; p < mesh.node_elem_offsets[i + 1]; ++p) {
      const Index e = mesh.node_elem[p];
      const Index* c = mesh.element(e);
      for (int a = 0; a < k; ++a)
        if (c[a] == i) sum += model.element_node_mass[static_cast<size_t>(e) * k + a];
    }
    model.mass[i] = sum;
  }
}

namespace {

/// The position of `whole` in the ascending list of a part's whole ids, -1 when absent.
Index local_of(const std::vector<Index>& whole_ids, Index whole) {
  const auto it = std::lower_bound(whole_ids.begin(), whole_ids.end(), whole);
  return it != whole_ids.end() && *it == whole ? static_cast<Index>(it - whole_ids.begin()) : -1;
}

}  // namespace

Index Model::local_element(Index whole) const {
  if (!is_part()) return whole < mesh.num_elements() ? whole : -1;
  return local_of(part.element_index, whole);
}

Index Model::local_node(Index whole) const {
  if (!is_part()) return whole < mesh.num_nodes() ? whole : -1;
  return local_of(part.node_index, whole);
}

std::size_t model_bytes(const Model& m) {
  std::size_t bytes = 0;
  for_each_array(m, [&](const auto& v) { bytes += v.capacity() * sizeof(v[0]); });
  for (const ShellBody& s : m.shells) {
    bytes += s.mesh.reference.capacity() * sizeof(Vec3) + s.mesh.triangles.capacity() * sizeof(s.mesh.triangles[0]) +
             (s.mesh.patch.capacity() + s.mesh.patch_offsets.capacity() + s.vertex_slot.capacity() +
              s.vertex_slot_offsets.capacity()) * sizeof(Index) + s.vertex_slot_weight.capacity() * sizeof(double);
    for (const ShellPatchSet& set : s.sets)
      bytes += set.triangle.capacity() * sizeof(Index) + set.reference.capacity() * sizeof(set.reference[0]);
  }
  return bytes;
}

}  // namespace shatter
