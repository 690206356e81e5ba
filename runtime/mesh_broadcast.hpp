#pragma once
// The start-up rank's mesh sent to every rank (build_model on several ranks:
// one rank meshes, the others receive; docs/parallel.md).
#include <mpi.h>

#include "mesh/mesh.hpp"

namespace shatter {

/// After the call every rank of `comm` holds `root`'s mesh, bit for bit
/// (collective; every array, the node -> element CSR included).
void broadcast_mesh(Mesh& mesh, int root, MPI_Comm comm);

}  // namespace shatter
