#pragma once
// Part files (docs/parallel.md "Part files"): the parts of a model for R ranks,
// cut once by `shatter partition` and written one file per rank, so that a run
// on R ranks reads on each rank its own part and no rank meshes, reads or
// holds the whole model. A part file holds exactly what the start-up rank
// would send that rank (model_part.hpp), so the run is bit for bit the one
// that meshes at start-up.
//
// Layout of DIR/part-<r>-of-<R>.bin (native byte order, 8-byte words):
//   magic      16 bytes "shatter parts" padded with zeros
//   version    uint64 3 (2: the surface's triangles in the part; 1: and its nodes' rows)
//   rank, ranks  uint64: r and R
//   physics    uint64 length, then the text of physics_keys() of the scene it
//              was cut from (a run names the first key that differs)
//   part       put_part()'s bytes: a header of 8 words, then every array of
//              the part as its length (uint64) and its elements
//   fnv1a64    uint64: FNV-1a of every byte before it (runtime/fnv1a.hpp)
#include <mpi.h>

#include <cstdint>
#include <filesystem>
#include <vector>

#include "runtime/model.hpp"

namespace shatter {

/// The file of rank `rank` among `ranks` in `dir`.
std::filesystem::path part_file(const std::filesystem::path& dir, int rank, int ranks);

/// Cuts `whole` (a model built on one rank) into its parts for `ranks` ranks and
/// writes each into part_file(dir, r, ranks) (through a temporary file, renamed
/// when complete). Returns each part file's size in bytes, by rank. Throws InputError
/// when the scene cannot run on parts (shells, or fracture with contact: these
/// hold the whole model on every rank) or cannot take `ranks` ranks, and Error
/// when a file cannot be written.
std::vector<std::uintmax_t> write_part_files(const Model& whole, int ranks, const std::filesystem::path& dir);

/// Reads this rank's part file from `dir` into `model` (which holds the scene and
/// the materials of the run). Throws InputError on every rank of `comm`, with
/// the message of the lowest rank that found it, when a file is missing, is
/// of another rank count, was cut from a scene whose physics differ (naming
/// the first key that does), or fails its hash (damaged or truncated).
/// Collective.
void read_part_file(Model& model, const std::filesystem::path& dir, MPI_Comm comm);

}  // namespace shatter
