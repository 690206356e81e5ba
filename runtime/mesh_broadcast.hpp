#pragma once
// The start-up rank's mesh sent to every rank (build_model on several ranks:
// one rank meshes, the others receive; docs/parallel.md).
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"

namespace shatter {

/// Broadcasts a vector of trivially copyable values from `root` (its size first; collective).
template <class T>
void broadcast_vector(std::vector<T>& v, int root, MPI_Comm comm) {
  std::uint64_t n = v.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, root, comm);
  v.resize(n);
  const std::uint64_t bytes = n * sizeof(T);
  constexpr std::uint64_t kChunk = std::uint64_t{1} << 30;  // MPI counts are int
  for (std::uint64_t at = 0; at < bytes; at += kChunk)
    MPI_Bcast(reinterpret_cast<char*>(v.data()) + at, static_cast<int>(std::min(kChunk, bytes - at)), MPI_BYTE,
              root, comm);
}

/// After the call every rank of `comm` holds `root`'s mesh, bit for bit
/// (collective; every array, the node -> element CSR included).
void broadcast_mesh(Mesh& mesh, int root, MPI_Comm comm);

}  // namespace shatter
