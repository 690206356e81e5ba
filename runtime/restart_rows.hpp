#pragma once
// A restart on parts without a dataset read whole (docs/checkpoint.md "On
// several ranks"): the rows a part needs of the datasets it cannot pick from
// its own ids (each node's rank among the prescribed ones, the cracked facets
// of its elements and their cohesive elements) are found by the ranks
// together. Each rank reads one block of each such dataset (rows
// [N r / R, N (r + 1) / R)), and the parts ask the blocks' ranks for theirs:
// O(rows held + N / R) per rank, no array of the whole model.
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// The first row of each of `ranks` blocks of `rows` rows, and `rows` last.
std::vector<std::size_t> block_firsts(std::size_t rows, int ranks);

/// A part's rows of bc_mask, and each prescribed one's rank among the whole model's.
struct PartBcRows {
  std::vector<std::uint8_t> mask;  ///< per row asked
  std::vector<Index> bc_rows;      ///< per prescribed row asked, its rank
  Index whole_bc_nodes = 0;        ///< prescribed nodes of the whole model
};
/// block: this rank's block of the whole bc_mask (of `n` rows); rows: the part's node rows,
/// ascending. Collective.
PartBcRows part_bc_rows(std::span<const std::uint8_t> block, std::size_t n, std::span<const Index> rows,
                        MPI_Comm comm);

/// A part's cracked facets and their cohesive elements.
struct PartFacets {
  std::vector<Index> facet_rows;        ///< rows of facet_gid, ascending
  std::vector<GlobalId> facet_gid;      ///< their gids
  std::vector<Index> cohesive_rows;     ///< rows of cohesive_facet, ascending
  std::vector<GlobalId> cohesive_gid;   ///< their facets' gids
  std::string error;                    ///< this rank's: a cohesive element's facet that facet_gid lacks
};
/// facet_block, cohesive_block: this rank's blocks of facet_gid (ascending gids 4 g + face, g
/// the gid of the facet's smaller element) and cohesive_facet (each cohesive element's facet
/// gid), of `facets` and `cohesive` rows; elements: the gids of the part's elements,
/// ascending. The part's facets are those of its elements (gid / 4 among them). Collective.
PartFacets part_facets(std::span<const GlobalId> facet_block, std::size_t facets,
                       std::span<const GlobalId> cohesive_block, std::size_t cohesive,
                       std::span<const GlobalId> elements, MPI_Comm comm);

}  // namespace shatter
