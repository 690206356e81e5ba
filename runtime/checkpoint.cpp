#include "runtime/checkpoint.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <span>
#include <sstream>

#include "kernels/error.hpp"
#include "runtime/alltoall_lists.hpp"
#include "runtime/comm_place.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/fnv1a.hpp"
#include "runtime/first_failure.hpp"
#include "runtime/hdf5_failure.hpp"
#include "runtime/hdf5_rows.hpp"
#include "runtime/restart_rows.hpp"
#include "runtime/row_blocks.hpp"
#include "runtime/scene_keys.hpp"

namespace shatter {
namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 rows are written as 3 packed doubles");

constexpr const char* kFormat = "shatter-checkpoint";
// 2: the step controller's state; 3: the scene's physics keys; 4: the ledger's contact_work;
// 6: the free rigid bodies' states; 7: the datasets' hashes by rows (row_hash)
constexpr long kVersion = 7;
/// The first version whose datasets carry row_hash sums (older: FNV-1a of the bytes in order).
constexpr long kRowHashVersion = 7;
/// Rows (Vec3) per free rigid body in /state/rigid_bodies.
constexpr std::size_t kRigidRows = 10;

/// A free rigid body's state as kRigidRows rows: (mass, 0, 0), principal moments, centre,
/// velocity, the orientation's columns, angular momentum, force, torque.
void rigid_rows(const RigidBodyState& b, std::vector<Vec3>& rows) {
  rows.push_back(Vec3(b.mass, 0, 0));
  for (const Vec3& v : {b.inertia, b.centre, b.velocity}) rows.push_back(v);
  for (int c = 0; c < 3; ++c) rows.push_back(b.orientation.col(c));
  for (const Vec3& v : {b.angular_momentum, b.force, b.torque}) rows.push_back(v);
}

RigidBodyState rigid_from_rows(const Vec3* r) {
  RigidBodyState b;
  b.mass = r[0].x();
  b.inertia = r[1], b.centre = r[2], b.velocity = r[3];
  for (int c = 0; c < 3; ++c) b.orientation.col(c) = r[4 + c];
  b.angular_momentum = r[7], b.force = r[8], b.torque = r[9];
  return b;
}
constexpr long kOldestVersion = 2;  // read without the physics check

/// A hash of every attribute of a checkpoint (names and values; a dataset's
/// own hash of its bytes is one of them), summed so that the order of
/// writing and reading does not matter. Stored as the root attribute
/// state_fnv1a64: a file spliced from two checkpoints, each part intact in
/// itself (datasets pass their own hashes), fails it.
struct StateDigest {
  std::uint64_t sum = 0;
  void add(const char* name, const void* value, std::size_t bytes) {
    sum += fnv1a(value, bytes, fnv1a(name, std::strlen(name)));
  }
};

/// HDF5 types of the arrays a checkpoint holds: file() as stored
/// (little-endian, fixed width), memory() as held.
template <class T>
struct FileType;
template <>
struct FileType<double> {
  static constexpr hsize_t numbers = 1;  // per element of the vector
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct FileType<Vec3> : FileType<double> {
  static constexpr hsize_t numbers = 3;
};
template <>
struct FileType<std::int64_t> {
  static constexpr hsize_t numbers = 1;
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t memory() { return H5T_NATIVE_INT64; }
};
template <>
struct FileType<std::int32_t> {
  static constexpr hsize_t numbers = 1;
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t memory() { return H5T_NATIVE_INT32; }
};
template <>
struct FileType<std::int8_t> {
  static constexpr hsize_t numbers = 1;
  static hid_t file() { return H5T_STD_I8LE; }
  static hid_t memory() { return H5T_NATIVE_INT8; }
};
template <>
struct FileType<std::uint8_t> {
  static constexpr hsize_t numbers = 1;
  static hid_t file() { return H5T_STD_U8LE; }
  static hid_t memory() { return H5T_NATIVE_UINT8; }
};
template <>
struct FileType<std::array<std::int32_t, 3>> : FileType<std::int32_t> {
  static constexpr hsize_t numbers = 3;
};
template <>
struct FileType<FacetState> : FileType<std::uint8_t> {};
static_assert(sizeof(FacetState) == 1);

// ---- writing: every failure throws Error naming the temporary file ----

/// A creation property list (`cls`: file, group or dataset) without the
/// objects' time stamps: a checkpoint's bytes are its state's alone, whenever
/// it is written.
H5Id untimed(hid_t cls) {
  H5Id p(H5Pcreate(cls), H5Pclose);
  if (p.valid()) H5Pset_obj_track_times(p.get(), false);
  return p;
}

/// Version 7's hash of one row of a dataset: FNV-1a of its bytes, seeded with
/// the row's index. A dataset's hash (attribute fnv1a64) is the sum of its
/// rows' (mod 2^64): each rank hashes the rows it writes or reads, and the
/// sums add up (a flipped byte changes its row's term, a moved row its index).
std::uint64_t row_hash(std::uint64_t row, const void* bytes, std::size_t size) {
  return fnv1a(bytes, size, fnv1a(&row, sizeof row));
}

/// The sum of row_hash over `rows` rows of `row_bytes` bytes from `data`, the first one row `first`.
std::uint64_t rows_hash(const void* data, std::size_t rows, std::size_t row_bytes, std::uint64_t first) {
  std::uint64_t h = 0;
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < rows; ++i) h += row_hash(first + i, p + i * row_bytes, row_bytes);
  return h;
}

/// Writes a checkpoint with every rank of `comm` (one rank: the whole
/// state). Attributes are written by every rank with the same value; each
/// dataset's rows go from the ranks holding them to the contiguous blocks of
/// row_blocks.hpp, which the ranks write collectively (MPI-IO), and its hash
/// is the sum of the blocks' row hashes.
struct Writer {
  std::string path;
  MPI_Comm comm = MPI_COMM_SELF;
  int rank = 0, ranks = 1;
  mutable StateDigest digest;
  std::string who() const { return "checkpoint " + path; }
  void check(bool ok, const std::string& what) const {
    SHATTER_REQUIRE(ok, who() << ": " << hdf5_write_failure(what));
  }
  /// Runs `write`, then agrees with the other ranks in one reduction, which
  /// also sums `partial` over them (returned): a failure on any rank throws
  /// the same Error on every rank (first_failure), at the same point, so that
  /// the handles are closed in the same order everywhere.
  template <class Write>
  std::uint64_t agreed(Write write, std::uint64_t partial = 0) const {
    std::string error;
    try {
      write();
    } catch (const Error& e) {
      error = e.what();
    }
    if (ranks > 1) {
      std::array<std::uint64_t, 2> v{error.empty() ? 0u : 1u, partial};
      MPI_Allreduce(MPI_IN_PLACE, v.data(), 2, MPI_UINT64_T, MPI_SUM, comm);
      if (v[0] > 0) error = first_failure(error, comm);
      partial = v[1];
    }
    if (!error.empty()) throw Error(error);
    return partial;
  }
  long total(long mine) const {
    if (ranks > 1) MPI_Allreduce(MPI_IN_PLACE, &mine, 1, MPI_LONG, MPI_SUM, comm);
    return mine;
  }
  /// The first row of this rank's `count` rows after those of the lower ranks.
  long offset(long count) const {
    long first = 0;
    if (ranks > 1) MPI_Exscan(&count, &first, 1, MPI_LONG, MPI_SUM, comm);
    return rank == 0 ? 0 : first;
  }
  void attribute(hid_t object, const char* name, hid_t type, const void* value) const {
    errno = 0;  // hdf5_write_failure reports the OS's reason of a failure in here
    H5Id space(H5Screate(H5S_SCALAR), H5Sclose);
    H5Id attr(H5Acreate2(object, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    check(space.valid() && attr.valid() && H5Awrite(attr.get(), type, value) >= 0,
          std::string("write attribute ") + name);
    digest.add(name, value, H5Tget_size(type));
  }
  void number(hid_t object, const char* name, double v) const {
    attribute(object, name, H5T_NATIVE_DOUBLE, &v);
  }
  void integer(hid_t object, const char* name, long v) const {
    const std::int64_t w = v;
    attribute(object, name, H5T_NATIVE_INT64, &w);
  }
  void text(hid_t object, const char* name, const std::string& s) const {
    H5Id type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(type.valid() && H5Tset_size(type.get(), s.size() + 1) >= 0, "make a string type");
    attribute(object, name, type.get(), s.c_str());
  }
  /// Dataset `name` of `total` rows of `cols` numbers (a Vec3 is 3), of
  /// which this rank holds `rows` (whole row indices, ascending) in `mine`
  /// (one rank: all of them, in order), with attribute fnv1a64.
  template <class T>
  void array(hid_t group, const char* name, std::span<const T> mine, std::span<const Index> rows, long total,
             hsize_t cols = 1) const {
    const hsize_t per = cols / FileType<T>::numbers;  // T's per row
    SHATTER_REQUIRE(per * FileType<T>::numbers == cols && mine.size() % per == 0,
                    "checkpoint: dataset " << name << " is not a whole number of rows");
    std::vector<T> moved;
    std::span<const T> block = mine;
    long first = 0;
    if (ranks > 1) {
      const std::vector<std::byte> bytes = to_row_blocks(rows, std::as_bytes(mine), static_cast<int>(per * sizeof(T)),
                                                         static_cast<Index>(total), comm);
      moved.resize(bytes.size() / sizeof(T));
      std::memcpy(static_cast<void*>(moved.data()), bytes.data(), bytes.size());
      block = moved;
      first = row_block(static_cast<Index>(total), rank, ranks).first;
    }
    placed(group, name, block, first, total, cols);
  }
  /// Dataset `name` of `total` rows of which this rank writes the rows
  /// [first, first + block rows), with attribute fnv1a64.
  template <class T>
  void placed(hid_t group, const char* name, std::span<const T> block, long first, long total, hsize_t cols) const {
    const hsize_t per = cols / FileType<T>::numbers;
    const hsize_t count = block.size() / per;
    // One reduction: the outcome and the hash.
    const std::uint64_t h = agreed(
        [&] {
          write_rows(group, name, FileType<T>::memory(), FileType<T>::file(), block.data(),
                     Rows{count, static_cast<hsize_t>(first), static_cast<hsize_t>(total)}, cols, who(),
                     untimed(H5P_DATASET_CREATE).get(), ranks > 1);
        },
        rows_hash(block.data(), count, per * sizeof(T), static_cast<std::uint64_t>(first)));
    H5Id dset(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    check(dset.valid(), std::string("open dataset ") + name);
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &h);
  }
  template <class T>
  void array(hid_t group, const char* name, const std::vector<T>& mine, std::span<const Index> rows, long total,
             hsize_t cols = 1) const {
    array(group, name, std::span<const T>(mine), rows, total, cols);
  }
};

/// `a`'s elements `rows` (`per` consecutive values per row).
template <class T>
std::vector<T> picked(const std::vector<T>& a, std::span<const Index> rows, std::size_t per = 1) {
  std::vector<T> out;
  out.reserve(rows.size() * per);
  for (Index r : rows) out.insert(out.end(), a.begin() + static_cast<std::ptrdiff_t>(r * per),
                                  a.begin() + static_cast<std::ptrdiff_t>((r + 1) * per));
  return out;
}

/// fsync of a file or folder; throws naming it.
void sync_path(const std::filesystem::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags);
  SHATTER_REQUIRE(
      fd >= 0, "checkpoint: cannot open " << p.string() << " to sync it: " << std::strerror(errno));
  const int rc = ::fsync(fd);
  ::close(fd);
  SHATTER_REQUIRE(rc == 0,
                  "checkpoint: cannot sync " << p.string() << ": " << std::strerror(errno));
}

// ---- reading: every failure throws InputError naming the checkpoint ----

struct Reader {
  std::string path;
  long version = kVersion;  ///< the file's, once read
  mutable StateDigest digest;
  /// A dataset read in part: its stored hash and this rank's sum of its counted rows.
  struct PartHash {
    std::string name;
    std::uint64_t stored = 0, sum = 0;
  };
  mutable std::vector<PartHash> parts;
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError("--restart " + path + ": " + why);
  }
  void require(bool ok, const std::string& why) const {
    if (!ok) fail(why);
  }
  void attribute(hid_t object, const char* name, hid_t type, void* value) const {
    H5Id attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    require(attr.valid() && H5Aread(attr.get(), type, value) >= 0,
            std::string("attribute ") + name +
                " is missing or unreadable (truncated or corrupted checkpoint?)");
    digest.add(name, value, H5Tget_size(type));
  }
  double number(hid_t object, const char* name) const {
    double v = 0;
    attribute(object, name, H5T_NATIVE_DOUBLE, &v);
    return v;
  }
  long integer(hid_t object, const char* name) const {
    std::int64_t v = 0;
    attribute(object, name, H5T_NATIVE_INT64, &v);
    return static_cast<long>(v);
  }
  std::string text(hid_t object, const char* name) const {
    H5Id attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    require(attr.valid(),
            std::string("attribute ") + name + " is missing (not a shatter checkpoint?)");
    H5Id type(H5Aget_type(attr.get()), H5Tclose);
    require(
        type.valid() && H5Tget_class(type.get()) == H5T_STRING && !H5Tis_variable_str(type.get()),
        std::string("attribute ") + name + " is not a string");
    std::string s(H5Tget_size(type.get()), '\0');
    require(H5Aread(attr.get(), type.get(), s.data()) >= 0,
            std::string("cannot read attribute ") + name);
    digest.add(name, s.data(), s.size());
    return s.c_str();
  }
  /// Requires the dataspace `space` of dataset `name` to be `expected` x `cols`.
  void require_shape(const H5Id& space, const char* name, std::size_t expected, hsize_t cols) const {
    std::array<hsize_t, 2> dims{0, 0};
    require(space.valid() && H5Sget_simple_extent_ndims(space.get()) == 2 &&
                H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) == 2 && dims[1] == cols &&
                dims[0] == expected,
            std::string("dataset ") + name + " has the wrong shape (expected " + std::to_string(expected) +
                " x " + std::to_string(cols) + ")");
  }
  /// The hash of `rows` rows of `row_bytes` bytes from `data`, the first
  /// one row `first`, for this file's version: a sum of row_hash, or (before
  /// version 7) FNV-1a of the bytes in order, continuing `h`.
  std::uint64_t hash(const void* data, std::size_t rows, std::size_t row_bytes, std::size_t first,
                     std::uint64_t h) const {
    return version >= kRowHashVersion ? h + rows_hash(data, rows, row_bytes, first) : fnv1a(data, rows * row_bytes, h);
  }
  std::uint64_t empty_hash() const { return version >= kRowHashVersion ? 0 : fnv1a(nullptr, 0); }
  H5Id open(hid_t group, const char* name, std::size_t expected, hsize_t cols, H5Id& space) const {
    H5Id dset(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    require(dset.valid(), std::string("dataset ") + name + " is missing (truncated or corrupted checkpoint?)");
    space = H5Id(H5Dget_space(dset.get()), H5Sclose);
    require_shape(space, name, expected, cols);
    return dset;
  }
  /// Reads rows [first, first + count) of `dset` into `out`.
  template <class T>
  void read_rows(const H5Id& dset, const H5Id& space, const char* name, hsize_t first, hsize_t count, hsize_t cols,
                 std::vector<T>& out) const {
    const std::array<hsize_t, 2> start{first, 0}, size{count, cols};
    out.resize(count * cols / FileType<T>::numbers);
    if (count == 0) return;
    H5Id memory(H5Screate_simple(2, size.data(), nullptr), H5Sclose);
    require(memory.valid() &&
                H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, size.data(), nullptr) >= 0 &&
                H5Dread(dset.get(), FileType<T>::memory(), memory.get(), space.get(), H5P_DEFAULT, out.data()) >= 0,
            std::string("cannot read dataset ") + name + " (truncated or corrupted checkpoint?)");
  }
  void check_hash(const H5Id& dset, const char* name, std::uint64_t h) const {
    std::uint64_t stored = 0;
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &stored);
    require(stored == h, std::string("dataset ") + name + " fails its hash check (corrupted checkpoint)");
  }
  /// Reads a dataset written by Writer::array: `expected` rows of `cols`
  /// numbers, hash checked.
  template <class T>
  std::vector<T> array(hid_t group, const char* name, std::size_t expected, hsize_t cols = 1) const {
    H5Id space;
    const H5Id dset = open(group, name, expected, cols, space);
    std::vector<T> a;
    read_rows(dset, space, name, 0, expected, cols, a);
    check_hash(dset, name, hash(a.data(), expected, a.size() * sizeof(T) / std::max<std::size_t>(expected, 1), 0,
                                empty_hash()));
    return a;
  }
  std::vector<Vec3> rows(hid_t group, const char* name, std::size_t expected) const {
    return array<Vec3>(group, name, expected, 3);
  }
  /// Rows per block of a dataset read in pieces: what memory holds of it.
  static constexpr hsize_t kBlock = 1 << 16;
  /// Reads a dataset written by Writer::array (`expected` rows of `cols`
  /// numbers) block by block, calling visit(first row, the block's values):
  /// memory holds one block, and the whole dataset's hash is checked.
  template <class T, class Visit>
  void blocks(hid_t group, const char* name, std::size_t expected, hsize_t cols, Visit visit) const {
    H5Id space;
    const H5Id dset = open(group, name, expected, cols, space);
    std::vector<T> block;
    std::uint64_t h = empty_hash();
    for (hsize_t first = 0; first < expected; first += kBlock) {
      const hsize_t count = std::min<hsize_t>(kBlock, expected - first);
      read_rows(dset, space, name, first, count, cols, block);
      h = hash(block.data(), count, block.size() * sizeof(T) / count, first, h);
      visit(static_cast<std::size_t>(first), std::span<const T>(block));
    }
    check_hash(dset, name, h);
  }
  /// The rows `keep` (ascending) of such a dataset: a part's rows of a
  /// whole-model array. Version 7: only those rows are read (runs of them
  /// with gaps of at most kGap rows, up to kBlock rows a read); the row
  /// hashes of those whose `counted` is set (this rank is their owner: over
  /// the ranks, every row once) are added to the dataset's partial sum,
  /// checked by check_parts(). Before version 7 the whole dataset is read
  /// block by block and its hash checked here.
  template <class T>
  std::vector<T> array(hid_t group, const char* name, std::size_t expected, hsize_t cols,
                       std::span<const Index> keep, std::span<const char> counted) const {
    const std::size_t per = cols / FileType<T>::numbers;
    std::vector<T> out;
    out.reserve(keep.size() * per);
    require(keep.empty() || (keep.front() >= 0 && static_cast<std::size_t>(keep.back()) < expected),
            std::string("dataset ") + name + " has fewer rows than the model");
    if (version < kRowHashVersion) {
      std::size_t k = 0;
      blocks<T>(group, name, expected, cols, [&](std::size_t first, std::span<const T> block) {
        for (; k < keep.size() && static_cast<std::size_t>(keep[k]) < first + block.size() / per; ++k)
          out.insert(out.end(), block.begin() + (keep[k] - first) * per, block.begin() + (keep[k] - first + 1) * per);
      });
      return out;
    }
    constexpr Index kGap = 64;
    H5Id space;
    const H5Id dset = open(group, name, expected, cols, space);
    std::uint64_t h = 0;
    std::vector<T> run;
    for (std::size_t i = 0; i < keep.size();) {
      std::size_t j = i + 1;
      while (j < keep.size() && keep[j] - keep[j - 1] <= kGap && static_cast<hsize_t>(keep[j] - keep[i]) < kBlock) ++j;
      const Index first = keep[i];
      read_rows(dset, space, name, static_cast<hsize_t>(first), static_cast<hsize_t>(keep[j - 1] - first + 1), cols, run);
      for (; i < j; ++i) {
        const T* row = run.data() + static_cast<std::size_t>(keep[i] - first) * per;
        out.insert(out.end(), row, row + per);
        if (counted[i]) h += row_hash(static_cast<std::uint64_t>(keep[i]), row, per * sizeof(T));
      }
    }
    std::uint64_t stored = 0;
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &stored);
    parts.push_back({name, stored, h});
    return out;
  }
  std::vector<Vec3> rows(hid_t group, const char* name, std::size_t expected, std::span<const Index> keep,
                         std::span<const char> counted) const {
    return array<Vec3>(group, name, expected, 3, keep, counted);
  }
  /// Rank `rank`'s block of such a dataset, of `ranks` blocks (block_firsts). The block's
  /// rows are hashed here (over the ranks, every row once).
  template <class T>
  std::vector<T> block(hid_t group, const char* name, std::size_t expected, hsize_t cols, int rank,
                       int ranks) const {
    const std::vector<std::size_t> first = block_firsts(expected, ranks);
    std::vector<Index> keep(first[rank + 1] - first[rank]);
    std::iota(keep.begin(), keep.end(), static_cast<Index>(first[rank]));
    return array<T>(group, name, expected, cols, keep, std::vector<char>(keep.size(), 1));
  }
  /// The datasets read in part: each rank's sums of its counted rows, added
  /// over the ranks of `comm` (one reduction) and checked against the stored hashes.
  void check_parts(MPI_Comm comm) const {
    std::vector<std::uint64_t> sums;
    for (const PartHash& p : parts) sums.push_back(p.sum);
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_UINT64_T, MPI_SUM, comm);
    for (size_t i = 0; i < parts.size(); ++i)
      require(sums[i] == parts[i].stored,
              "dataset " + parts[i].name + " fails its hash check (corrupted checkpoint)");
  }
};

/// The bytes of the rows a rank writes (metadata aside; the reactions counted at every node).
std::uintmax_t checkpoint_bytes(const SimulationState& s, const CheckpointRows& rows, int nodes_per_element) {
  std::uintmax_t per_node = 6 * sizeof(Vec3);
  if (!s.fracture) return rows.nodes.size() * per_node;
  per_node += 3 * sizeof(Vec3) + sizeof(GlobalId) + sizeof(std::int32_t) + sizeof(double) + 1 + 3 * sizeof(std::int32_t);
  const std::uintmax_t per_cohesive = 2 * sizeof(GlobalId) + 1 + kCohesiveSlots * (1 + sizeof(Index)) +
                                      sizeof(double) + sizeof(Vec3) + kCohesivePoints * sizeof(double);
  return rows.nodes.size() * per_node + rows.elements.size() * nodes_per_element * sizeof(Index) +
         rows.cohesive.size() * per_cohesive;
}

/// /state/reactions: the rows of the prescribed nodes among `rows.nodes` (the
/// whole model's `nodes` rows at `whole`), in node order. They go to the node
/// blocks with a flag, and each block's flagged rows follow those of the lower blocks.
void write_reactions(const Writer& w, hid_t group, const Model& model, const SimulationState& s,
                     std::span<const Index> nodes, std::span<const Index> whole, long total_nodes) {
  // A node's reaction is the state's row of its rank among the prescribed nodes (Simulation::bc_nodes_).
  std::vector<Index> bc_rank(model.bc_mask.size(), -1);
  Index b = 0;
  for (size_t i = 0; i < bc_rank.size(); ++i)
    if (model.bc_mask[i]) bc_rank[i] = b++;
  SHATTER_REQUIRE(static_cast<size_t>(b) == s.reaction.size(),
                  "checkpoint: " << s.reaction.size() << " reactions for " << b << " prescribed nodes");
  using Flagged = std::array<double, 4>;  // the reaction and 1 where the node has one
  std::vector<Flagged> mine;
  mine.reserve(nodes.size());
  for (Index n : nodes) {
    const Index k = bc_rank[n];
    const Vec3 r = k >= 0 ? s.reaction[k] : Vec3::Zero();
    mine.push_back({r.x(), r.y(), r.z(), k >= 0 ? 1.0 : 0.0});
  }
  std::vector<Flagged> block = mine;
  if (w.ranks > 1) {
    const std::vector<std::byte> bytes = to_row_blocks(whole, std::as_bytes(std::span<const Flagged>(mine)),
                                                       sizeof(Flagged), static_cast<Index>(total_nodes), w.comm);
    block.resize(bytes.size() / sizeof(Flagged));
    std::memcpy(block.data(), bytes.data(), bytes.size());
  }
  std::vector<Vec3> rows;
  for (const Flagged& f : block)
    if (f[3] != 0) rows.emplace_back(f[0], f[1], f[2]);
  const long count = static_cast<long>(rows.size());
  w.placed(group, "reactions", std::span<const Vec3>(rows), w.offset(count), w.total(count), 3);
}

/// /fracture/facet_gid and facet_state: the facets (gid, state) of this
/// rank's cohesive elements, ascending by gid over the whole model. Sorted
/// by ranges: a facet goes to the rank whose share of the element global ids
/// [0, `gid_end`) holds its element's (gid / 4), which sorts what it
/// receives; the ranks' lists follow each other.
void write_facets(const Writer& w, hid_t group, std::vector<std::pair<GlobalId, FacetState>> mine, GlobalId gid_end) {
  std::sort(mine.begin(), mine.end());
  if (w.ranks > 1) {
    // (gid, state) as gid * 4 + state: one int64.
    std::vector<std::vector<std::int64_t>> to(w.ranks);
    size_t sent = 0;
    for (int d = 0; d < w.ranks; ++d) {
      const GlobalId end = gid_end * (d + 1) / w.ranks;
      for (; sent < mine.size() && mine[sent].first / 4 < end; ++sent)
        to[d].push_back(mine[sent].first * 4 + static_cast<std::int64_t>(mine[sent].second));
    }
    SHATTER_REQUIRE(sent == mine.size(), "checkpoint: a facet of an element global id past " << gid_end);
    std::vector<std::int64_t> received;
    for (const std::vector<std::int64_t>& from : alltoall_lists(to, MPI_INT64_T, w.comm))
      received.insert(received.end(), from.begin(), from.end());
    std::sort(received.begin(), received.end());
    mine.clear();
    for (std::int64_t r : received) mine.emplace_back(r / 4, static_cast<FacetState>(r % 4));
  }
  std::vector<GlobalId> gids;
  std::vector<FacetState> states;
  for (const auto& [gid, state] : mine) gids.push_back(gid), states.push_back(state);
  const long count = static_cast<long>(mine.size()), first = w.offset(count), total = w.total(count);
  w.placed(group, "facet_gid", std::span<const GlobalId>(gids), first, total, 1);
  w.placed(group, "facet_state", std::span<const FacetState>(states), first, total, 1);
}

volatile std::sig_atomic_t g_stop_signal = 0;

void record_stop_signal(int sig) {
  g_stop_signal = sig;
}

}  // namespace

std::uint64_t model_fingerprint(const Model& model) {
  const Mesh& mesh = model.mesh;
  std::uint64_t h = fnv1a(&mesh.order, sizeof mesh.order);
  h = fnv1a(mesh.reference.data(), mesh.reference.size() * sizeof(Vec3), h);
  h = fnv1a(mesh.conn.data(), mesh.conn.size() * sizeof(Index), h);
  h = fnv1a(model.mass.data(), model.mass.size() * sizeof(double), h);
  h = fnv1a(model.bc_mask.data(), model.bc_mask.size(), h);
  return fnv1a(model.bc_velocity.data(), model.bc_velocity.size() * sizeof(Vec3), h);
}

std::uint64_t whole_fingerprint(const Model& model) {
  return model.is_part() ? model.part.fingerprint : model_fingerprint(model);
}

CheckpointRows all_rows(const Model& model, const SimulationState& state) {
  CheckpointRows rows;
  rows.nodes.resize(state.x.size());
  std::iota(rows.nodes.begin(), rows.nodes.end(), Index{0});
  if (state.fracture) {
    rows.elements.resize(model.mesh.num_elements());
    std::iota(rows.elements.begin(), rows.elements.end(), Index{0});
    const std::vector<Index>& whole = state.fracture->cohesive_whole;
    rows.cohesive.resize(whole.size());
    std::iota(rows.cohesive.begin(), rows.cohesive.end(), Index{0});
    std::sort(rows.cohesive.begin(), rows.cohesive.end(), [&](Index a, Index b) { return whole[a] < whole[b]; });
  }
  return rows;
}

void write_checkpoint(const std::filesystem::path& path, const Model& model,
                      const SimulationState& s, const std::string& failure, const CheckpointRows* given) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const CheckpointRows every = given ? CheckpointRows{} : all_rows(model, s);
  const CheckpointRows& r = given ? *given : every;
  Writer w{tmp.string(), r.comm, 0, 1, {}};
  w.ranks = comm_place(r.comm).size;
  if (w.ranks > 1) MPI_Comm_rank(r.comm, &w.rank);
  const QuietHdf5 quiet;
  const int k = model.mesh.nodes_per_element();
  const auto bytes = static_cast<std::uintmax_t>(w.total(static_cast<long>(checkpoint_bytes(s, r, k))));
  w.agreed([&] {
    const std::string lacking = w.rank == 0 ? lacking_space(tmp.parent_path(), bytes) : "";
    SHATTER_REQUIRE(lacking.empty(), w.who() << ": not written: " << lacking);
  });
  // The whole model's rows of this rank's nodes, elements and cohesive elements.
  std::vector<Index> node_rows, element_rows, cohesive_rows;
  for (Index n : r.nodes) node_rows.push_back(model.whole_node(n));
  for (Index e : r.elements) element_rows.push_back(model.whole_element(e));
  if (s.fracture)
    for (Index c : r.cohesive) cohesive_rows.push_back(s.fracture->cohesive_whole[c]);
  const long nodes = model.whole_nodes();
  try {
    H5Id fapl = w.ranks > 1 ? mpio_access(r.comm, w.who()) : H5Id(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    // Version 2 object headers and superblock: HDF5 checksums all metadata.
    w.check(
        fapl.valid() && H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST) >= 0,
        "select the latest file format");
    H5Id file;
    w.agreed([&] {
      errno = 0;
      file = H5Id(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, untimed(H5P_FILE_CREATE).get(), fapl.get()), H5Fclose);
      w.check(file.valid(), "create the file");
    });
    H5Id root_group(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose);
    w.check(root_group.valid(), "open the root group");
    const hid_t root = root_group.get();
    H5Id state, ledger;
    w.agreed([&] {
      w.text(root, "format", kFormat);
      w.integer(root, "version", kVersion);
      w.text(root, "scene", model.scene.name);
      w.integer(root, "nodes", s.model_nodes);
      w.integer(root, "elements", model.whole_elements());
      w.integer(root, "order", model.mesh.order);
      w.attribute(root, "fingerprint", H5T_NATIVE_UINT64, &s.model_fingerprint);
      w.integer(root, "step", s.step);
      w.number(root, "time", s.time);
      w.number(root, "dt", s.dt);
      w.number(root, "stable_dt", s.stable_dt);
      w.number(root, "control_dt", s.step_control.dt);
      w.number(root, "control_window_min", s.step_control.window_min);
      w.integer(root, "control_window_steps", s.step_control.window_steps);
      w.number(root, "total0", s.total0);
      w.number(root, "energy_scale", s.energy_scale);
      w.text(root, "failure", failure);
      const std::string physics = physics_keys(model.scene);
      const std::uint64_t scene_fp = fnv1a(physics.data(), physics.size());
      w.text(root, "physics", physics);
      w.attribute(root, "scene_fingerprint", H5T_NATIVE_UINT64, &scene_fp);
      w.integer(root, "history_every", model.scene.history_every);
      state = H5Id(H5Gcreate2(root, "state", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
      w.check(state.valid(), "create group /state");
      ledger = H5Id(H5Gcreate2(root, "ledger", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
      w.check(ledger.valid(), "create group /ledger");
      const Ledger& l = s.ledger;
      const hid_t g = ledger.get();
      w.number(g, "kinetic", l.kinetic);
      w.number(g, "strain", l.strain);
      w.number(g, "cohesive_stored", l.cohesive_stored);
      w.number(g, "cohesive_dissipated", l.cohesive_dissipated);
      w.number(g, "contact_dissipated", l.contact_dissipated);
      w.number(g, "contact_work", l.contact_work);
      w.number(g, "external_work", l.external_work);
      const char* p_names[3] = {"px", "py", "pz"};
      const char* L_names[3] = {"Lx", "Ly", "Lz"};
      for (int c = 0; c < 3; ++c) {
        w.number(g, p_names[c], l.momentum[c]);
        w.number(g, L_names[c], l.angular_momentum[c]);
      }
      w.integer(g, "contacts", l.contacts);
      w.integer(g, "cohesive_elements", l.cohesive_elements);
      w.integer(g, "fragments", l.fragments);
      w.integer(g, "contact_capped_steps", l.contact_capped_steps);
    });
    const hid_t st = state.get();
    w.array(st, "positions", picked(s.x, r.nodes), node_rows, nodes, 3);
    w.array(st, "velocities", picked(s.v, r.nodes), node_rows, nodes, 3);
    w.array(st, "accelerations", picked(s.a, r.nodes), node_rows, nodes, 3);
    w.array(st, "internal_forces", picked(s.f_int, r.nodes), node_rows, nodes, 3);
    w.array(st, "external_forces", picked(s.f_ext, r.nodes), node_rows, nodes, 3);
    write_reactions(w, st, model, s, r.nodes, node_rows, nodes);
    if (!s.rigid.empty()) {
      // Every rank holds them; the first writes them.
      std::vector<Vec3> rows;
      std::vector<Index> at;
      if (w.rank == 0)
        for (const RigidBodyState& b : s.rigid) rigid_rows(b, rows);
      for (Index i = 0; i < static_cast<Index>(rows.size()); ++i) at.push_back(i);
      w.array(st, "rigid_bodies", rows, at, static_cast<long>(kRigidRows * s.rigid.size()), 3);
    }
    if (s.fracture) {
      const FractureState& f = *s.fracture;
      const std::vector<Index>& n = r.nodes;
      H5Id group;
      w.agreed([&] {
        group = H5Id(H5Gcreate2(root, "fracture", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
        w.check(group.valid(), "create group /fracture");
        w.integer(group.get(), "nodes", nodes);
        w.integer(group.get(), "facets", w.total(static_cast<long>(r.cohesive.size())));
        w.integer(group.get(), "cohesive_elements", f.whole_cohesive);
        w.attribute(group.get(), "mesh_revision", H5T_NATIVE_UINT64, &f.mesh_revision);
      });
      const hid_t fr = group.get();
      w.array(fr, "reference", picked(f.reference, n), node_rows, nodes, 3);
      w.array(fr, "node_gid", picked(f.node_gid, n), node_rows, nodes);
      w.array(fr, "node_body", picked(f.node_body, n), node_rows, nodes);
      std::vector<Index> conn;
      for (Index e : r.elements)
        for (int a = 0; a < k; ++a) conn.push_back(model.whole_node(f.conn[static_cast<size_t>(e) * k + a]));
      w.array(fr, "conn", conn, element_rows, model.whole_elements(), k);
      w.array(fr, "mass", picked(f.mass, n), node_rows, nodes);
      w.array(fr, "bc_mask", picked(f.bc_mask, n), node_rows, nodes);
      w.array(fr, "bc_velocity", picked(f.bc_velocity, n), node_rows, nodes, 3);
      w.array(fr, "bc_condition", picked(f.bc_condition, n), node_rows, nodes, 3);
      w.array(fr, "initial_velocity", picked(f.initial_velocity, n), node_rows, nodes, 3);
      const CohesiveElements& c = f.cohesive;
      std::vector<std::pair<GlobalId, FacetState>> facets;
      std::vector<GlobalId> facet_of;
      std::vector<Index> side_nodes;
      for (Index i : r.cohesive) {
        const GlobalId gid = f.cohesive_facet_gid[i];
        const auto at = std::lower_bound(f.facet_gid.begin(), f.facet_gid.end(), gid) - f.facet_gid.begin();
        facets.emplace_back(gid, f.facet_state[at]);
        facet_of.push_back(gid);
        for (int j = 0; j < kCohesiveSlots; ++j) {
          const Index node = c.side_nodes[static_cast<size_t>(i) * kCohesiveSlots + j];
          side_nodes.push_back(node < 0 ? Index{-1} : model.whole_node(node));
        }
      }
      // The element global ids' range, for the facets' sort.
      GlobalId gid_end = model.mesh.elem_gid.empty()
                             ? 0
                             : *std::max_element(model.mesh.elem_gid.begin(), model.mesh.elem_gid.end()) + 1;
      if (w.ranks > 1) MPI_Allreduce(MPI_IN_PLACE, &gid_end, 1, MPI_INT64_T, MPI_MAX, w.comm);
      write_facets(w, fr, std::move(facets), gid_end);
      const long cohesive = f.whole_cohesive;
      w.array(fr, "cohesive_facet", facet_of, cohesive_rows, cohesive);
      w.array(fr, "cohesive_side_local", picked(c.side_local, r.cohesive, kCohesiveSlots), cohesive_rows, cohesive,
              kCohesiveSlots);
      w.array(fr, "cohesive_side_nodes", side_nodes, cohesive_rows, cohesive, kCohesiveSlots);
      w.array(fr, "cohesive_area", picked(c.area, r.cohesive), cohesive_rows, cohesive);
      w.array(fr, "cohesive_normal", picked(c.normal, r.cohesive), cohesive_rows, cohesive, 3);
      w.array(fr, "cohesive_delta_max", picked(c.delta_max, r.cohesive, kCohesivePoints), cohesive_rows, cohesive,
              kCohesivePoints);
    }
    w.agreed([&] {
      // Last: the sum of everything written above (not itself part of it).
      const std::uint64_t whole = w.digest.sum;
      w.attribute(root, "state_fnv1a64", H5T_NATIVE_UINT64, &whole);
      errno = 0;
      w.check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL) >= 0, "flush the file");
    });
    // Closed here (the handles above, on every rank alike): everything is in the OS's hands.
  } catch (const Error&) {
    // Every rank is here (agreed): the half-written file is of no use, and
    // its space lets the other files close on a full disk (disk_reserve.hpp).
    if (w.rank == 0) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
    }
    throw;
  }
  w.agreed([&] {
    if (w.rank != 0) return;
    sync_path(tmp, O_RDONLY);
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    SHATTER_REQUIRE(!ec, "checkpoint: cannot rename " << tmp.string() << " to " << path.string() << ": "
                                                      << ec.message());
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    sync_path(dir, O_RDONLY | O_DIRECTORY);
  });
}

namespace {

/// The whole model's fracture state, as written.
void read_fracture_whole(const Reader& r, hid_t fr, const Model& model, std::size_t elements, std::size_t facets,
                         FractureState& f) {
  const auto n = static_cast<std::size_t>(f.whole_nodes), nc = static_cast<std::size_t>(f.whole_cohesive);
  f.reference = r.rows(fr, "reference", n);
  f.node_gid = r.array<GlobalId>(fr, "node_gid", n);
  f.node_body = r.array<int>(fr, "node_body", n);
  f.conn = r.array<Index>(fr, "conn", elements, model.mesh.nodes_per_element());
  f.mass = r.array<double>(fr, "mass", n);
  f.bc_mask = r.array<std::uint8_t>(fr, "bc_mask", n);
  f.bc_velocity = r.rows(fr, "bc_velocity", n);
  f.bc_condition = r.array<std::array<std::int32_t, 3>>(fr, "bc_condition", n, 3);
  f.initial_velocity = r.rows(fr, "initial_velocity", n);
  f.facet_gid = r.array<GlobalId>(fr, "facet_gid", facets);
  f.facet_state = r.array<FacetState>(fr, "facet_state", facets);
  CohesiveElements& c = f.cohesive;
  f.cohesive_facet_gid = r.array<GlobalId>(fr, "cohesive_facet", nc);
  c.side_local = r.array<std::int8_t>(fr, "cohesive_side_local", nc, kCohesiveSlots);
  c.side_nodes = r.array<Index>(fr, "cohesive_side_nodes", nc, kCohesiveSlots);
  c.area = r.array<double>(fr, "cohesive_area", nc);
  c.normal = r.rows(fr, "cohesive_normal", nc);
  c.delta_max = r.array<double>(fr, "cohesive_delta_max", nc, kCohesivePoints);
}

/// Whether this rank (`rank`) is the owner of each of `gids` (facets by
/// global id, 4 g + face, g an element's global id held here): the owner of
/// element g (Model::Part::granule_rank).
std::vector<char> facet_owned(const Model& model, std::span<const GlobalId> gids, int rank) {
  std::vector<std::pair<GlobalId, Index>> by_gid;
  for (Index e = 0; e < model.mesh.num_elements(); ++e) by_gid.emplace_back(model.mesh.elem_gid[e], e);
  std::sort(by_gid.begin(), by_gid.end());
  std::vector<char> owned;
  for (GlobalId gid : gids) {
    const auto it = std::lower_bound(by_gid.begin(), by_gid.end(), std::pair<GlobalId, Index>(gid / 4, 0));
    SHATTER_REQUIRE(it != by_gid.end() && it->first == gid / 4, "checkpoint: facet " << gid << " is not held here");
    owned.push_back(model.part.granule_rank[model.whole_element(it->second) / ElementForces::kGranule] == rank);
  }
  return owned;
}

/// The owner of each of a part's node rows (f.node_rows, from its held
/// elements' conn rows f.conn): the smallest rank owning an element that uses
/// it, exact for the nodes of its owned elements (their whole star is here).
std::vector<int> fracture_node_owners(const Model& model, const FractureState& f) {
  const int k = model.mesh.nodes_per_element();
  const std::vector<Index>& held = model.part.element_index;
  const std::vector<Index>& rows = f.node_rows;
  std::vector<int> owner(rows.size(), std::numeric_limits<int>::max());
  for (size_t e = 0; e < held.size(); ++e) {
    const int er = model.part.granule_rank[held[e] / ElementForces::kGranule];
    for (int a = 0; a < k; ++a) {
      const auto at = std::lower_bound(rows.begin(), rows.end(), f.conn[e * k + a]) - rows.begin();
      owner[at] = std::min(owner[at], er);
    }
  }
  return owner;
}

/// A part's share of a checkpoint's fracture state (docs/parallel.md "Fracture
/// on parts"): the conn rows of its elements, the rows of their nodes, and
/// the facets and cohesive elements of facets one of whose elements it holds
/// (FractureState::restore keeps those it holds both of). Its rows are
/// hashed by their owners (Reader::array): an element's by its rank, a
/// node's by the smallest rank owning an element that uses it (every node of
/// an owned element has its whole star here), a facet's and its cohesive
/// element's by the owner of its element g. The rows of bc_mask, facet_gid
/// and cohesive_facet are found by the ranks together (restart_rows.hpp);
/// a refusal on any rank is every rank's before and after those collectives.
void read_fracture_part(const Reader& r, hid_t fr, const Model& model, std::size_t elements, std::size_t facets,
                        MPI_Comm comm, FractureState& f) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const auto n = static_cast<std::size_t>(f.whole_nodes), nc = static_cast<std::size_t>(f.whole_cohesive);
  const int k = model.mesh.nodes_per_element();
  const std::vector<Index>& held_elements = model.part.element_index;
  std::vector<std::uint8_t> bc_block;
  std::vector<GlobalId> facet_block, cohesive_block;
  std::string error;
  try {
    std::vector<char> owned_elements;
    for (Index e : held_elements) owned_elements.push_back(model.part.granule_rank[e / ElementForces::kGranule] == rank);
    f.conn = r.array<Index>(fr, "conn", elements, k, held_elements, owned_elements);
    f.node_rows = f.conn;
    std::sort(f.node_rows.begin(), f.node_rows.end());
    f.node_rows.erase(std::unique(f.node_rows.begin(), f.node_rows.end()), f.node_rows.end());
    r.require(f.node_rows.empty() || (f.node_rows.front() >= 0 && static_cast<std::size_t>(f.node_rows.back()) < n),
              "/fracture/conn names a node out of range (corrupted checkpoint?)");
    const std::span<const Index> rows = f.node_rows;
    std::vector<char> counted;
    for (int o : fracture_node_owners(model, f)) counted.push_back(o == rank);
    f.reference = r.rows(fr, "reference", n, rows, counted);
    f.node_gid = r.array<GlobalId>(fr, "node_gid", n, 1, rows, counted);
    f.node_body = r.array<int>(fr, "node_body", n, 1, rows, counted);
    f.mass = r.array<double>(fr, "mass", n, 1, rows, counted);
    f.bc_velocity = r.rows(fr, "bc_velocity", n, rows, counted);
    f.bc_condition = r.array<std::array<std::int32_t, 3>>(fr, "bc_condition", n, 3, rows, counted);
    f.initial_velocity = r.rows(fr, "initial_velocity", n, rows, counted);
    bc_block = r.block<std::uint8_t>(fr, "bc_mask", n, 1, rank, ranks);
    facet_block = r.block<GlobalId>(fr, "facet_gid", facets, 1, rank, ranks);
    cohesive_block = r.block<GlobalId>(fr, "cohesive_facet", nc, 1, rank, ranks);
    r.require(std::is_sorted(facet_block.begin(), facet_block.end()),
              "/fracture/facet_gid is not ascending (corrupted checkpoint?)");
  } catch (const InputError& e) {
    error = e.what();
  }
  if (error = first_failure(error, comm); !error.empty()) throw InputError(error);
  // The bc mask of the rows, and each prescribed row's rank among the whole model's.
  PartBcRows bc = part_bc_rows(bc_block, n, f.node_rows, comm);
  f.bc_mask = std::move(bc.mask);
  f.bc_rows = std::move(bc.bc_rows);
  f.whole_bc_nodes = bc.whole_bc_nodes;
  // Facets by global id, 4 g + face with g the smaller element's: those of the part's elements.
  std::vector<GlobalId> held(model.mesh.elem_gid.begin(), model.mesh.elem_gid.end());
  std::sort(held.begin(), held.end());
  PartFacets found = part_facets(facet_block, facets, cohesive_block, nc, held, comm);
  error = found.error;
  try {
    if (error.empty()) {
      f.facet_gid = std::move(found.facet_gid);
      f.facet_state = r.array<FacetState>(fr, "facet_state", facets, 1, found.facet_rows,
                                          facet_owned(model, f.facet_gid, rank));
      f.cohesive_whole = std::move(found.cohesive_rows);
      f.cohesive_facet_gid = std::move(found.cohesive_gid);
      const std::span<const Index> mine = f.cohesive_whole;
      const std::vector<char> owned = facet_owned(model, f.cohesive_facet_gid, rank);
      CohesiveElements& c = f.cohesive;
      c.side_local = r.array<std::int8_t>(fr, "cohesive_side_local", nc, kCohesiveSlots, mine, owned);
      c.side_nodes = r.array<Index>(fr, "cohesive_side_nodes", nc, kCohesiveSlots, mine, owned);
      c.area = r.array<double>(fr, "cohesive_area", nc, 1, mine, owned);
      c.normal = r.rows(fr, "cohesive_normal", nc, mine, owned);
      c.delta_max = r.array<double>(fr, "cohesive_delta_max", nc, kCohesivePoints, mine, owned);
    } else {
      r.fail(error);
    }
  } catch (const InputError& e) {
    error = e.what();
  }
  if (error = first_failure(error, comm); !error.empty()) throw InputError(error);
}

/// Whether this part (rank `rank`) is the owner of each of its nodes, as
/// hashed at a restart: the smallest rank whose owned elements use it
/// (Model::Part::node_ranks, whole for the nodes of its owned elements).
std::vector<char> nodes_owned(const Model& model, int rank) {
  const Model::Part& p = model.part;
  std::vector<char> owned;
  for (size_t i = 0; i + 1 < p.node_rank_offsets.size(); ++i)
    owned.push_back(p.node_rank_offsets[i] < p.node_rank_offsets[i + 1] && p.node_ranks[p.node_rank_offsets[i]] == rank);
  return owned;
}

/// read_checkpoint's reading on one rank (`rank` of the parts' ranks, `comm`).
SimulationState read_state(Reader& r, const std::filesystem::path& path, const Model& model, CheckpointRun* run,
                           int rank, MPI_Comm comm) {
  r.require(std::filesystem::is_regular_file(path), "no such file");
  const QuietHdf5 quiet;
  r.require(H5Fis_hdf5(path.c_str()) > 0,
            "not a readable HDF5 file (truncated or corrupted checkpoint?)");
  // STRONG: closing the file closes whatever a corrupted file left open.
  H5Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  r.require(fapl.valid() && H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) >= 0,
            "HDF5 failed to set up");
  H5Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  r.require(file.valid(), "cannot open the HDF5 file (truncated or corrupted checkpoint?)");
  H5Id root_group(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose);
  r.require(root_group.valid(), "cannot open the root group (truncated or corrupted checkpoint?)");
  const hid_t root = root_group.get();
  r.require(r.text(root, "format") == kFormat, "not a shatter checkpoint");
  const long version = r.integer(root, "version");
  r.require(version >= kOldestVersion && version <= kVersion,
            "checkpoint format version " + std::to_string(version) + ", this shatter reads " +
                std::to_string(kOldestVersion) + " to " + std::to_string(kVersion));
  r.version = version;
  const std::string scene = r.text(root, "scene");
  r.require(scene == model.scene.name, "the checkpoint is of scene '" + scene + "', not of '" +
                                           model.scene.name + "' (" + model.scene.file + ")");
  if (run) run->history_every = 0;  // version 2: not recorded
  if (version >= 3) {
    const std::string physics = r.text(root, "physics");
    std::uint64_t scene_fp = 0;
    r.attribute(root, "scene_fingerprint", H5T_NATIVE_UINT64, &scene_fp);
    r.require(scene_fp == fnv1a(physics.data(), physics.size()),
              "attribute physics fails its hash check (corrupted checkpoint)");
    const KeyDifference d = first_difference(physics, physics_keys(model.scene));
    r.require(d.key.empty(), d.key + " is " + d.a + " in the checkpoint's scene and " + d.b + " in " +
                                 model.scene.file +
                                 "; expected the physics of the checkpoint's run (a restart may "
                                 "change only time.end, time.safety, time.dt, output and checkpoint)");
    const long history_every = r.integer(root, "history_every");
    if (run) run->history_every = history_every;
  }
  const long nodes = r.integer(root, "nodes"), elements = r.integer(root, "elements"),
             order = r.integer(root, "order");
  if (nodes != model.whole_nodes() || elements != model.whole_elements() || order != model.mesh.order) {
    std::ostringstream os;
    os << "the checkpoint's model has " << nodes << " nodes and " << elements << " TET"
       << (order == 2 ? 10 : 4) << " elements, the scene's has " << model.whole_nodes()
       << " nodes and " << model.whole_elements() << " TET" << model.mesh.nodes_per_element()
       << " elements (another mesh: element_size, shape or order changed?)";
    r.fail(os.str());
  }
  std::uint64_t fp = 0;
  r.attribute(root, "fingerprint", H5T_NATIVE_UINT64, &fp);
  r.require(fp == whole_fingerprint(model),
            "the model differs from the checkpoint's (mesh coordinates, masses or boundary "
            "conditions changed)");

  SimulationState s;
  s.model_fingerprint = fp;
  s.model_nodes = nodes;
  // With fracture, the state's node arrays include the split copies.
  std::size_t n = model.whole_nodes();
  const bool has_fracture = H5Lexists(root, "fracture", H5P_DEFAULT) > 0;
  r.require(has_fracture == model.scene.fracture_enabled(),
            has_fracture ? "the checkpoint has a fracture state but the scene has no fracture block"
                         : "the scene has fracture but the checkpoint has no fracture state (written by an "
                           "older shatter?)");
  r.require(!has_fracture || version >= 5,
            "the fracture state is of format version " + std::to_string(version) +
                " (facets by index); this shatter reads fracture states of version 5 on (facets by global id): "
                "run the scene again from the start");
  if (has_fracture) {
    H5Id group(H5Gopen2(root, "fracture", H5P_DEFAULT), H5Gclose);
    r.require(group.valid(), "group /fracture is unreadable (truncated or corrupted checkpoint?)");
    const hid_t fr = group.get();
    const long fn = r.integer(fr, "nodes"), facets = r.integer(fr, "facets"),
               cohesive = r.integer(fr, "cohesive_elements");
    r.require(fn >= nodes && facets >= 0 && cohesive >= 0 && cohesive <= facets,
              "/fracture has impossible counts (corrupted checkpoint?)");
    n = static_cast<std::size_t>(fn);
    FractureState& f = s.fracture.emplace();
    r.attribute(fr, "mesh_revision", H5T_NATIVE_UINT64, &f.mesh_revision);
    f.whole_nodes = static_cast<Index>(fn);
    f.whole_cohesive = static_cast<Index>(cohesive);
    if (model.is_part()) {
      read_fracture_part(r, fr, model, static_cast<std::size_t>(elements), static_cast<std::size_t>(facets), comm, f);
    } else {
      read_fracture_whole(r, fr, model, static_cast<std::size_t>(elements), static_cast<std::size_t>(facets), f);
    }
  }
  s.step = r.integer(root, "step");
  s.time = r.number(root, "time");
  s.dt = r.number(root, "dt");
  s.stable_dt = r.number(root, "stable_dt");
  s.step_control.dt = r.number(root, "control_dt");
  s.step_control.window_min = r.number(root, "control_window_min");
  s.step_control.window_steps = r.integer(root, "control_window_steps");
  s.total0 = r.number(root, "total0");
  s.energy_scale = r.number(root, "energy_scale");
  H5Id state(H5Gopen2(root, "state", H5P_DEFAULT), H5Gclose);
  r.require(state.valid(), "group /state is missing (truncated or corrupted checkpoint?)");
  const auto rigid = static_cast<std::size_t>(std::count_if(model.scene.bodies.begin(), model.scene.bodies.end(),
                                                            [](const BodySpec& body) { return body.has_rigid_state(); }));
  if (rigid > 0) {
    r.require(version >= 6, "the checkpoint is of format version " + std::to_string(version) +
                                ", before rigid bodies' states (version 6)");
    const std::vector<Vec3> rows = r.rows(state.get(), "rigid_bodies", kRigidRows * rigid);
    for (std::size_t k = 0; k < rigid; ++k) s.rigid.push_back(rigid_from_rows(rows.data() + kRigidRows * k));
  }
  std::size_t b = 0;
  if (model.is_part()) {
    // A part reads its own rows (the whole state never in memory): with fracture
    // those of its elements' nodes after the splits (read_fracture_part).
    const FractureState* f = s.fracture ? &*s.fracture : nullptr;
    b = f ? f->whole_bc_nodes : model.part.whole_bc_nodes;
    const std::span<const Index> nodes = f ? f->node_rows : model.part.node_index;
    // Each row hashed by its owner (read_fracture_part, nodes_owned), a reaction by its node's.
    std::vector<char> counted, bc_counted;
    if (f) {
      const std::vector<int> owner = fracture_node_owners(model, *f);
      for (int o : owner) counted.push_back(o == rank);
    } else {
      counted = nodes_owned(model, rank);
    }
    const std::span<const std::uint8_t> mask = f ? std::span<const std::uint8_t>(f->bc_mask) : model.bc_mask;
    for (size_t i = 0; i < mask.size(); ++i)
      if (mask[i]) bc_counted.push_back(counted[i]);
    s.x = r.rows(state.get(), "positions", n, nodes, counted);
    s.v = r.rows(state.get(), "velocities", n, nodes, counted);
    s.a = r.rows(state.get(), "accelerations", n, nodes, counted);
    s.f_int = r.rows(state.get(), "internal_forces", n, nodes, counted);
    s.f_ext = r.rows(state.get(), "external_forces", n, nodes, counted);
    s.reaction = r.rows(state.get(), "reactions", b, f ? std::span<const Index>(f->bc_rows) : model.part.bc_index,
                        bc_counted);
  } else {
    for (std::uint8_t m : s.fracture ? s.fracture->bc_mask : model.bc_mask) b += m != 0;
    s.x = r.rows(state.get(), "positions", n);
    s.v = r.rows(state.get(), "velocities", n);
    s.a = r.rows(state.get(), "accelerations", n);
    s.f_int = r.rows(state.get(), "internal_forces", n);
    s.f_ext = r.rows(state.get(), "external_forces", n);
    s.reaction = r.rows(state.get(), "reactions", b);
  }

  H5Id ledger(H5Gopen2(root, "ledger", H5P_DEFAULT), H5Gclose);
  r.require(ledger.valid(), "group /ledger is missing (truncated or corrupted checkpoint?)");
  const hid_t g = ledger.get();
  Ledger& l = s.ledger;
  l.kinetic = r.number(g, "kinetic");
  l.strain = r.number(g, "strain");
  l.cohesive_stored = r.number(g, "cohesive_stored");
  l.cohesive_dissipated = r.number(g, "cohesive_dissipated");
  l.contact_dissipated = r.number(g, "contact_dissipated");
  // Before version 4 the contact's first-order work was in contact_dissipated (e < 1 or
  // mu > 0) or in no term (e = 1, mu = 0): it continues from 0, the total stays as it was.
  l.contact_work = version >= 4 ? r.number(g, "contact_work") : 0.0;
  l.external_work = r.number(g, "external_work");
  const char* p_names[3] = {"px", "py", "pz"};
  const char* L_names[3] = {"Lx", "Ly", "Lz"};
  for (int c = 0; c < 3; ++c) {
    l.momentum[c] = r.number(g, p_names[c]);
    l.angular_momentum[c] = r.number(g, L_names[c]);
  }
  l.contacts = r.integer(g, "contacts");
  l.cohesive_elements = r.integer(g, "cohesive_elements");
  l.fragments = r.integer(g, "fragments");
  l.contact_capped_steps = r.integer(g, "contact_capped_steps");
  if (version >= 3) {
    r.text(root, "failure");  // read for the digest: every attribute written is read
    const std::uint64_t sum = r.digest.sum;
    std::uint64_t whole = 0;
    r.attribute(root, "state_fnv1a64", H5T_NATIVE_UINT64, &whole);
    r.require(whole == sum,
              "the parts of the file do not belong together (spliced from different checkpoints, or "
              "corrupted): the whole-file hash state_fnv1a64 fails");
  }
  return s;
}

}  // namespace

SimulationState read_checkpoint(const std::filesystem::path& path, const Model& model, CheckpointRun* run,
                                MPI_Comm comm) {
  Reader r{path.string(), kVersion, {}, {}};
  if (!model.is_part()) return read_state(r, path, model, run, 0, comm);
  // The parts read together: one rank's refusal is every rank's, then the
  // datasets' hashes are the sums of their owners' rows.
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  SimulationState s;
  std::string error;
  try {
    s = read_state(r, path, model, run, rank, comm);
  } catch (const InputError& e) {
    error = e.what();
  }
  error = first_failure(error, comm);
  if (!error.empty()) throw InputError(error);
  r.check_parts(comm);
  return s;
}

void truncate_rows_after(const std::filesystem::path& csv, long step) {
  std::ifstream in(csv);
  if (!in)
    throw InputError("--restart: " + csv.string() +
                     " is missing; it is needed to continue the run's rows");
  std::string header, line, kept;
  if (!std::getline(in, header) || header.rfind("step,", 0) != 0)
    throw InputError("--restart: " + csv.string() + " has no header row starting with 'step,'");
  kept = header + '\n';
  while (std::getline(in, line)) {
    // A row cut short by a kill has no newline and no trustworthy step: dropped with the rest.
    if (in.eof()) break;
    if (std::stol(line.substr(0, line.find(','))) > step) break;
    kept += line + '\n';
  }
  in.close();
  const std::filesystem::path tmp = csv.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << kept;
    SHATTER_REQUIRE(out.flush(), "cannot write " << tmp.string());
  }
  std::filesystem::rename(tmp, csv);
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = record_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;  // a second signal of the same kind ends the process at once
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int stop_signal() {
  return g_stop_signal;
}

}  // namespace shatter
