#include "runtime/mesh_broadcast.hpp"

#include <cstdint>

namespace shatter {
namespace {

/// Broadcasts a vector of trivially copyable values (its size first).
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

}  // namespace

void broadcast_mesh(Mesh& mesh, int root, MPI_Comm comm) {
  std::uint64_t head[2] = {static_cast<std::uint64_t>(mesh.order), mesh.revision};
  MPI_Bcast(head, 2, MPI_UINT64_T, root, comm);
  mesh.order = static_cast<int>(head[0]);
  mesh.revision = head[1];
  broadcast_vector(mesh.reference, root, comm);
  broadcast_vector(mesh.node_gid, root, comm);
  broadcast_vector(mesh.node_body, root, comm);
  broadcast_vector(mesh.conn, root, comm);
  broadcast_vector(mesh.elem_gid, root, comm);
  broadcast_vector(mesh.elem_body, root, comm);
  broadcast_vector(mesh.elem_material, root, comm);
  broadcast_vector(mesh.node_elem_offsets, root, comm);
  broadcast_vector(mesh.node_elem, root, comm);
}

}  // namespace shatter
