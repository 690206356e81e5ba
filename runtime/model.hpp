#pragma once
// The model a scene describes: one mesh holding every body, the materials,
// the per-element reference constants, lumped masses, boundary conditions
// and initial velocities. Built once, before the run.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <tuple>
#include <vector>

#include "kernels/neo_hookean.hpp"
#include "kernels/tet10.hpp"
#include "mesh/mesh.hpp"
#include "mesh/shape_estimate.hpp"
#include "runtime/scene.hpp"
#include "runtime/shell_model.hpp"

namespace shatter {

struct Model {
  Scene scene;
  Mesh mesh;
  std::vector<NeoHookean> materials;  ///< by material index

  // Per-element reference constants (struct of arrays; one set per order).
  std::vector<Mat3> tet4_Dm_inv;             ///< TET4: inverse reference edge matrix, 1/m
  std::vector<Tet10Reference> tet10_ref;     ///< TET10: dxi/dX and weights per point
  std::vector<double> element_volume;        ///< reference volume, m^3
  std::vector<double> element_node_mass;     ///< [e*k + a]: lumped mass element e gives node a, kg

  std::vector<double> mass;                  ///< lumped nodal mass, kg
  std::vector<std::uint8_t> bc_mask;         ///< per node: bit k set = component k prescribed
  /// per node: prescribed components at amplitude 1, the velocity (m/s) or
  /// displacement (m) of the condition bc_condition names
  std::vector<Vec3> bc_velocity;
  /// per node and component: the boundary condition (index into
  /// scene.boundary_conditions) prescribing it, -1 for a free component
  std::vector<std::array<std::int32_t, 3>> bc_condition;
  /// A boundary face carrying a load: element, local face (kTetFaces row), load (scene.loads index).
  struct LoadFace {
    Index element = 0;
    std::int32_t face = 0, load = 0;
  };
  /// The faces of the scene's loads, by load, then element and local face
  /// (the whole model's order; a part holds those of its held elements, in that order).
  std::vector<LoadFace> load_faces;
  std::vector<Vec3> initial_velocity;        ///< per node, m/s

  /// Total mass and volume of each body (of the whole model); a shell's
  /// volume is its thickness times its reference limit surface's area.
  std::vector<double> body_mass, body_volume;

  /// The shell bodies, in body order (docs/shells.md "The runtime"): their
  /// control vertices are the model's last nodes (ShellBody::first_node), in
  /// no element of `mesh`. Only on a whole model (a scene with shells holds the
  /// whole model on every rank: docs/parallel.md "Shells on ranks").
  std::vector<ShellBody> shells;

  /// Wall seconds the start-up rank spent meshing (Gmsh) or reading the bodies
  /// and ordering their elements (summary.json mesh_time); 0 on the other ranks.
  /// With part files (build_model's `parts`), each rank's seconds reading its part.
  double mesh_seconds = 0;

  /// A rank's part of the whole model (docs/parallel.md "Owned subdomains"):
  /// its owned elements and their ghost layer, ascending in the whole
  /// model's order, and the nodes they use (with contact, and the rigid
  /// bodies' surface nodes). With fracture, two ghost layers (holds_two_layers()).
  /// Empty `element_index`: this model is the whole one (one rank, or a
  /// scene every rank holds whole).
  struct Part {
    std::vector<Index> element_index;  ///< per element: its index in the whole model
    std::vector<Index> node_index;     ///< per node: its index in the whole model
    std::vector<int> block_color;      ///< per element block held here (ascending): the whole model's block color
    std::vector<int> granule_rank;     ///< per granule of the whole model: its owner (METIS)
    /// CSR per node: the ranks whose owned elements use it, ascending (empty
    /// with two layers, where every node a rank reads has its whole star held)
    std::vector<Index> node_rank_offsets;
    std::vector<int> node_ranks;
    std::vector<Index> bc_index;       ///< per node with a prescribed component: its rank among the whole model's
    /// Contact scenes: of the whole model's contact surface (build_contact_surface), the
    /// rigid bodies' surface nodes (ascending whole ids) with their volume owners, which
    /// every part holds. The rest is not held: each rank names the triangles of its own
    /// elements and finds its surface nodes in its mesh (named_surface.hpp). The part holds
    /// the rows of its elements' nodes and of the rigid bodies' surface nodes only
    /// (docs/parallel.md "Patches with their own topology").
    std::vector<Index> rigid_surface_node;
    std::vector<int> rigid_surface_owner;
    double surface_edge = 0;  ///< the surface's median edge length (median_edge_length)
    Index whole_elements = 0, whole_nodes = 0, whole_bc_nodes = 0;
    std::uint64_t fingerprint = 0;     ///< model_fingerprint() of the whole model
  } part;
  bool is_part() const { return !part.element_index.empty(); }
  /// A part of a fracture scene (docs/parallel.md "Fracture on parts"): it
  /// holds a second ghost layer (every element sharing a node with the
  /// first), so every node of an owned or first-layer element has its whole
  /// star here and splits as on one rank.
  bool holds_two_layers() const { return is_part() && scene.fracture_enabled(); }
  Index whole_element(Index e) const { return is_part() ? part.element_index[e] : e; }
  Index whole_node(Index n) const { return is_part() ? part.node_index[n] : n; }
  /// The local index of the whole model's element `whole`, -1 when not held here.
  Index local_element(Index whole) const;
  /// The local index of the whole model's node `whole`, -1 when not held here. A part's
  /// node_index must ascend (a part without fracture: its nodes keep the whole order).
  Index local_node(Index whole) const;
  Index whole_elements() const { return is_part() ? part.whole_elements : mesh.num_elements(); }
  Index whole_nodes() const { return is_part() ? part.whole_nodes : mesh.num_nodes(); }
};

/// f(array) for every array of the model (model_bytes; a part travels in this order).
template <class M, class F>
void for_each_array(M& m, F f) {
  f(m.mesh.reference), f(m.mesh.node_gid), f(m.mesh.node_body), f(m.mesh.conn), f(m.mesh.elem_gid);
  f(m.mesh.elem_body), f(m.mesh.elem_material), f(m.mesh.node_elem_offsets), f(m.mesh.node_elem);
  f(m.tet4_Dm_inv), f(m.tet10_ref), f(m.element_volume), f(m.element_node_mass), f(m.mass), f(m.bc_mask);
  f(m.bc_velocity), f(m.bc_condition), f(m.load_faces), f(m.initial_velocity), f(m.body_mass), f(m.body_volume);
  f(m.part.element_index), f(m.part.node_index), f(m.part.block_color), f(m.part.granule_rank);
  f(m.part.node_rank_offsets), f(m.part.node_ranks), f(m.part.bc_index);
  f(m.part.rigid_surface_node), f(m.part.rigid_surface_owner);
}

/// The model's per-node arrays that node splitting grows, in one order
/// (FractureState holds the same: node_arrays there; copy_node_arrays and
/// append_node_row copy between them).
inline auto node_arrays(Model& m) {
  return std::tie(m.mesh.reference, m.mesh.node_gid, m.mesh.node_body, m.mass, m.bc_mask, m.bc_velocity,
                  m.bc_condition, m.initial_velocity);
}
inline auto node_arrays(const Model& m) {
  return std::tie(m.mesh.reference, m.mesh.node_gid, m.mesh.node_body, m.mass, m.bc_mask, m.bc_velocity,
                  m.bc_condition, m.initial_velocity);
}
/// Every per-node array of `to` becomes that of `from`.
template <class To, class From>
void copy_node_arrays(To& to, const From& from) {
  std::apply([&](auto&... t) { std::apply([&](const auto&... f) { ((t = f), ...); }, node_arrays(from)); },
             node_arrays(to));
}
/// Node n's row of every per-node array of `from`, appended to those of `to`.
template <class To, class From>
void append_node_row(To& to, const From& from, Index n) {
  std::apply([&](auto&... t) { std::apply([&](const auto&... f) { (t.push_back(f[n]), ...); }, node_arrays(from)); },
             node_arrays(to));
}

/// Whether every rank of a run on several holds the whole model of `scene`
/// rather than its part: cracks in contact, and shells (docs/parallel.md
/// "Limits", "Shells on ranks").
bool whole_model_on_every_rank(const Scene& scene);

/// Mesh every body, check the meshes, and compute every constant of the model.
/// On several ranks of `comm` (collective) rank 0 meshes and computes the
/// whole model. A scene without both fracture and contact is then cut: rank 0
/// partitions it (METIS granules) and sends every rank its part (owned
/// elements and ghost layers, Model::Part), keeping its own; otherwise every
/// rank receives the mesh and computes the whole model. Throws InputError
/// (bad scene or mesh) on every rank.
/// Before meshing, a primitive beyond kMaxCoordinate, or primitives whose
/// estimated elements (estimated_elements) add up to more than
/// `max_elements`, throw InputError naming the body's key.
/// With `parts` (a folder of `shatter partition`'s files, part_files.hpp) each rank
/// reads its own part instead, and nothing is meshed.
Model build_model(const Scene& scene, MPI_Comm comm = MPI_COMM_SELF, double max_elements = kDefaultMaxElements,
                  const std::filesystem::path& parts = {});

/// Recompute the lumped masses of `nodes` from element_node_mass (after node splitting).
void recompute_node_masses(Model& model, const std::vector<Index>& nodes);

/// Bytes held by the model's arrays.
std::size_t model_bytes(const Model& model);

}  // namespace shatter
