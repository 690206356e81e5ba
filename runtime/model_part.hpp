#pragma once
// A rank's part of the model (docs/parallel.md "Owned subdomains"): the
// start-up rank cuts the whole model along the METIS granule partition and
// sends every rank its owned elements, the ghost layer (every element with a
// node an owned element uses) and the nodes they use, with their indices in
// the whole model, the whole model's block colors, the granule owners and
// the ranks touching each node (Model::Part). With contact, the part also
// holds the whole contact surface's topology (issue 16). With fracture, a
// second ghost layer, so that nodes split on the part as on one rank
// (docs/parallel.md "Fracture on parts").
#include <mpi.h>

#include <cstdint>
#include <functional>

#include "runtime/model.hpp"

namespace shatter {

class Decomposition;

/// Rank 0 of `comm` cuts `whole` and sends every other rank its part, which
/// they receive into `model` (holding the scene and materials); rank 0's
/// `model` becomes its own part and the whole model is freed. Collective.
void distribute_parts(Model& model, MPI_Comm comm);

/// Cuts `whole` into its parts for `ranks` ranks (the partition distribute_parts
/// uses) and hands each to each(rank, part) (without scene and materials), rank
/// 0's last. Holds the whole model and one part at a time.
void cut_parts(const Model& whole, int ranks, const std::function<void(int, Model&&)>& each);

/// A part's arrays as bytes, in a fixed order, through put(data, bytes).
void put_part(const Model& part, const std::function<void(const void*, std::uint64_t)>& put);
/// The inverse of put_part through get(data, bytes); `limit`: the bytes that can
/// be read. Returns false (the part incomplete) when a length read would go
/// past the limit, so a damaged length never allocates more than is there.
bool get_part(Model& part, std::uint64_t limit, const std::function<void(void*, std::uint64_t)>& get);

/// After a split on parts (docs/parallel.md "Fracture on parts"): the whole
/// model's indices of this part's nodes from `first` on (the split copies,
/// ascending by name), those of the copies with a prescribed component among
/// the whole model's such nodes, and the whole counts. Each copy is named
/// once over the ranks, by its owner (the smallest rank owning an element of
/// its star); the whole model's new nodes take the indices after its nodes
/// in the order of their names, as one rank numbers them. A copy no owner
/// names (of the outer ghost layer, split from a partial star) gets -1: it
/// is never read. Mesh::revision is bumped on every rank when the whole model
/// gained nodes, and only then.
/// Call after the model's per-node arrays grew with the mesh.
/// Collective; returns the number of nodes the whole model gained.
Index number_split_nodes(Model& part, Index first, std::uint64_t revision, const Decomposition& dec);

}  // namespace shatter
