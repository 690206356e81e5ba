#include "runtime/mesh_broadcast.hpp"

#include <cstdint>

namespace shatter {

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
