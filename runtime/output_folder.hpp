#pragma once
// The output folder of a run, checked before the model is built
// (docs/errors.md, "Output folder and plots"): a folder that cannot be
// created or written, or a folder or device where an output file goes, is bad input
// (InputError, exit 2) found before any meshing, not an HDF5 failure later.
#include <mpi.h>

#include <filesystem>
#include <functional>
#include <string>

namespace shatter {

/// Creates `dir` (and its parents) on rank 0 of `comm`, writes the disk
/// reserve in it (disk_reserve.hpp: a read-only or full folder fails here),
/// and checks that none of the run's output files (history.csv, bodies.csv,
/// fields.h5, fields.xdmf, summary.json, fragments.csv, checkpoint.h5) is a
/// folder, and that no HDF5 one is a device. Throws InputError on every
/// rank, naming the folder and the OS reason (errno), when it fails.
void prepare_output_folder(const std::filesystem::path& dir, MPI_Comm comm);

/// Throws InputError naming `file` when it is a folder, or with `devices`
/// any other file that is not a regular file (following links: /dev/full):
/// each output file is replaced by the run, a folder in its place cannot be,
/// and HDF5 cannot close a file on a device that fails its writes.
void refuse_non_file_at(const std::filesystem::path& file, bool devices);

/// Runs `check` on rank 0 of `comm`; an InputError it throws is thrown, with
/// the same message, on every rank (a collective: every rank calls it).
void on_root_for_all(MPI_Comm comm, const std::function<void()>& check);

}  // namespace shatter
