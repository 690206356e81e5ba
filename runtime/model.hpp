#pragma once
// The model a scene describes: one mesh holding every body, the materials,
// the per-element reference constants, lumped masses, boundary conditions
// and initial velocities. Built once, before the run.
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "kernels/neo_hookean.hpp"
#include "kernels/tet10.hpp"
#include "mesh/mesh.hpp"
#include "runtime/scene.hpp"

namespace shatter {

struct Model {
  Scene scene;
  Mesh mesh;
  std::vector<NeoHookean> materials;  ///< by material index

  // Per-element reference constants (struct of arrays; one set per order).
  std::vector<Mat3> tet4_Dm_inv;             ///< TET4: inverse reference edge matrix, 1/m
  std::vector<Tet10Reference> tet10_ref;     ///< TET10: dN/dX and weights per point
  std::vector<double> element_volume;        ///< reference volume, m^3
  std::vector<double> element_node_mass;     ///< [e*k + a]: lumped mass element e gives node a, kg

  std::vector<double> mass;                  ///< lumped nodal mass, kg
  std::vector<std::uint8_t> bc_mask;         ///< per node: bit k set = component k prescribed
  std::vector<Vec3> bc_velocity;             ///< per node: prescribed velocity components, m/s
  std::vector<Vec3> initial_velocity;        ///< per node, m/s

  /// Total mass and volume of each body.
  std::vector<double> body_mass, body_volume;
};

/// Mesh every body, check the meshes, and compute every constant of the model.
/// On several ranks of `comm` (collective) rank 0 meshes and sends the mesh
/// to the others, which compute the constants from it: Gmsh runs once, and
/// every rank holds the same model. Throws InputError (bad scene or mesh) on
/// every rank.
Model build_model(const Scene& scene, MPI_Comm comm = MPI_COMM_SELF);

/// Recompute the lumped masses of `nodes` from element_node_mass (after node splitting).
void recompute_node_masses(Model& model, const std::vector<Index>& nodes);

/// Bytes held by the model's arrays.
std::size_t model_bytes(const Model& model);

}  // namespace shatter
