#pragma once
// A rank's part of the model (docs/parallel.md "Owned subdomains"): the
// start-up rank cuts the whole model along the METIS granule partition and
// sends every rank its owned elements, the ghost layer (every element with a
// node an owned element uses) and the nodes they use, with their indices in
// the whole model, the whole model's block colors, the granule owners and
// the ranks touching each node (Model::Part). With contact, the part also
// holds the whole contact surface (its state is shared by every rank until
// the contact surface is distributed, issue 16).
#include <mpi.h>

#include "runtime/model.hpp"

namespace shatter {

/// Rank 0 of `comm` cuts `whole` and sends every other rank its part, which
/// they receive into `model` (holding the scene and materials); rank 0's
/// `model` becomes its own part and the whole model is freed. Collective.
void distribute_parts(Model& model, MPI_Comm comm);

}  // namespace shatter
