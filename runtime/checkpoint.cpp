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
#include <span>
#include <sstream>

#include "kernels/error.hpp"
#include "runtime/fnv1a.hpp"
#include "runtime/hdf5_failure.hpp"
#include "runtime/scene_keys.hpp"

namespace shatter {
namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 rows are written as 3 packed doubles");

constexpr const char* kFormat = "shatter-checkpoint";
// 2: the step controller's state; 3: the scene's physics keys; 4: the ledger's contact_work;
// 6: the free rigid bodies' states
constexpr long kVersion = 6;
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

/// Owns one HDF5 identifier and closes it with the matching H5?close.
class H5Handle {
 public:
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  H5Handle(H5Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  ~H5Handle() {
    if (id_ >= 0) close_(id_);
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
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
H5Handle untimed(hid_t cls) {
  H5Handle p(H5Pcreate(cls), H5Pclose);
  if (p.valid()) H5Pset_obj_track_times(p.get(), false);
  return p;
}

struct Writer {
  std::string path;
  mutable StateDigest digest;
  void check(bool ok, const std::string& what) const {
    SHATTER_REQUIRE(ok, "checkpoint " << path << ": " << hdf5_write_failure(what));
  }
  void attribute(hid_t object, const char* name, hid_t type, const void* value) const {
    errno = 0;  // hdf5_write_failure reports the OS's reason of a failure in here
    H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    H5Handle attr(H5Acreate2(object, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
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
    H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(type.valid() && H5Tset_size(type.get(), s.size() + 1) >= 0, "make a string type");
    attribute(object, name, type.get(), s.c_str());
  }
  /// A dataset of rows of `cols` numbers from `a` (a Vec3 is 3 numbers),
  /// with attribute fnv1a64, the hash of its bytes.
  template <class T>
  void array(hid_t group, const char* name, const std::vector<T>& a, hsize_t cols = 1) const {
    const hsize_t numbers = a.size() * FileType<T>::numbers;
    SHATTER_REQUIRE(numbers % cols == 0, "checkpoint: dataset " << name << " is not a whole number of rows");
    const std::array<hsize_t, 2> dims{numbers / cols, cols};
    errno = 0;
    H5Handle space(H5Screate_simple(2, dims.data(), nullptr), H5Sclose);
    H5Handle dset(
        H5Dcreate2(group, name, FileType<T>::file(), space.get(), H5P_DEFAULT, untimed(H5P_DATASET_CREATE).get(),
                   H5P_DEFAULT),
        H5Dclose);
    check(space.valid() && dset.valid(), std::string("create dataset ") + name);
    if (!a.empty())
      check(H5Dwrite(dset.get(), FileType<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data()) >= 0,
            std::string("write dataset ") + name);
    const std::uint64_t h = fnv1a(a.data(), a.size() * sizeof(T));
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &h);
  }
  void rows(hid_t group, const char* name, const std::vector<Vec3>& a) const { array(group, name, a, 3); }
};

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
  mutable StateDigest digest;
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError("--restart " + path + ": " + why);
  }
  void require(bool ok, const std::string& why) const {
    if (!ok) fail(why);
  }
  void attribute(hid_t object, const char* name, hid_t type, void* value) const {
    H5Handle attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
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
    H5Handle attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    require(attr.valid(),
            std::string("attribute ") + name + " is missing (not a shatter checkpoint?)");
    H5Handle type(H5Aget_type(attr.get()), H5Tclose);
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
  void require_shape(const H5Handle& space, const char* name, std::size_t expected, hsize_t cols) const {
    std::array<hsize_t, 2> dims{0, 0};
    require(space.valid() && H5Sget_simple_extent_ndims(space.get()) == 2 &&
                H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) == 2 && dims[1] == cols &&
                dims[0] == expected,
            std::string("dataset ") + name + " has the wrong shape (expected " + std::to_string(expected) +
                " x " + std::to_string(cols) + ")");
  }
  /// Reads a dataset written by Writer::array: `expected` rows of `cols`
  /// numbers, hash checked.
  template <class T>
  std::vector<T> array(hid_t group, const char* name, std::size_t expected, hsize_t cols = 1) const {
    H5Handle dset(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    require(dset.valid(),
            std::string("dataset ") + name + " is missing (truncated or corrupted checkpoint?)");
    H5Handle space(H5Dget_space(dset.get()), H5Sclose);
    require_shape(space, name, expected, cols);
    std::vector<T> a(expected * cols / FileType<T>::numbers);
    if (expected > 0)
      require(H5Dread(dset.get(), FileType<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data()) >= 0,
              std::string("cannot read dataset ") + name + " (truncated or corrupted checkpoint?)");
    std::uint64_t h = 0;
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &h);
    require(h == fnv1a(a.data(), a.size() * sizeof(T)),
            std::string("dataset ") + name + " fails its hash check (corrupted checkpoint)");
    return a;
  }
  std::vector<Vec3> rows(hid_t group, const char* name, std::size_t expected) const {
    return array<Vec3>(group, name, expected, 3);
  }
  /// Reads a dataset written by Writer::array (`expected` rows of `cols`
  /// numbers) block by block, calling visit(first row, the block's values):
  /// memory holds one block, and the whole dataset's hash is checked.
  template <class T, class Visit>
  void blocks(hid_t group, const char* name, std::size_t expected, hsize_t cols, Visit visit) const {
    H5Handle dset(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    require(dset.valid(), std::string("dataset ") + name + " is missing (truncated or corrupted checkpoint?)");
    H5Handle space(H5Dget_space(dset.get()), H5Sclose);
    require_shape(space, name, expected, cols);
    constexpr hsize_t kBlock = 1 << 16;
    std::vector<T> block;
    std::uint64_t h = fnv1a(nullptr, 0);
    for (hsize_t first = 0; first < expected; first += kBlock) {
      const std::array<hsize_t, 2> start{first, 0}, count{std::min<hsize_t>(kBlock, expected - first), cols};
      block.resize(count[0] * cols / FileType<T>::numbers);
      H5Handle memory(H5Screate_simple(2, count.data(), nullptr), H5Sclose);
      require(memory.valid() &&
                  H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr) >= 0 &&
                  H5Dread(dset.get(), FileType<T>::memory(), memory.get(), space.get(), H5P_DEFAULT, block.data()) >= 0,
              std::string("cannot read dataset ") + name + " (truncated or corrupted checkpoint?)");
      h = fnv1a(block.data(), block.size() * sizeof(T), h);
      visit(static_cast<std::size_t>(first), std::span<const T>(block));
    }
    std::uint64_t stored = 0;
    attribute(dset.get(), "fnv1a64", H5T_NATIVE_UINT64, &stored);
    require(stored == h, std::string("dataset ") + name + " fails its hash check (corrupted checkpoint)");
  }
  /// The rows `keep` (ascending) of such a dataset, read by blocks(): a
  /// part's rows of a whole-model array.
  template <class T>
  std::vector<T> array(hid_t group, const char* name, std::size_t expected, hsize_t cols,
                       std::span<const Index> keep) const {
    const std::size_t per = cols / FileType<T>::numbers;
    std::vector<T> out;
    out.reserve(keep.size() * per);
    std::size_t k = 0;
    blocks<T>(group, name, expected, cols, [&](std::size_t first, std::span<const T> block) {
      for (; k < keep.size() && static_cast<std::size_t>(keep[k]) < first + block.size() / per; ++k)
        out.insert(out.end(), block.begin() + (keep[k] - first) * per, block.begin() + (keep[k] - first + 1) * per);
    });
    require(k == keep.size(), std::string("dataset ") + name + " has fewer rows than the model");
    return out;
  }
  std::vector<Vec3> rows(hid_t group, const char* name, std::size_t expected, std::span<const Index> keep) const {
    return array<Vec3>(group, name, expected, 3, keep);
  }
};

template <class... Arrays>
std::uintmax_t bytes_of(const Arrays&... a) {
  return ((a.size() * sizeof(typename Arrays::value_type)) + ...);
}

/// The bytes of the arrays a checkpoint of `s` holds (its metadata aside).
std::uintmax_t checkpoint_bytes(const SimulationState& s) {
  std::uintmax_t bytes = bytes_of(s.x, s.v, s.a, s.f_int, s.f_ext, s.reaction);
  if (s.fracture) {
    const FractureState& f = *s.fracture;
    const CohesiveElements& c = f.cohesive;
    bytes += bytes_of(f.reference, f.node_gid, f.node_body, f.conn, f.mass, f.bc_mask, f.bc_velocity,
                      f.bc_condition, f.initial_velocity, f.facet_gid, f.facet_state, f.cohesive_facet_gid,
                      c.side_local, c.side_nodes, c.area, c.normal,
                      c.delta_max);
  }
  return bytes;
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

void write_checkpoint(const std::filesystem::path& path, const Model& model,
                      const SimulationState& s, const std::string& failure) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const Writer w{tmp.string(), {}};
  const QuietHdf5 quiet;
  const std::string lacking = lacking_space(tmp.parent_path(), checkpoint_bytes(s));
  SHATTER_REQUIRE(lacking.empty(), "checkpoint " << tmp.string() << ": not written: " << lacking);
  try {
    H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    // Version 2 object headers and superblock: HDF5 checksums all metadata.
    w.check(
        fapl.valid() && H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST) >= 0,
        "select the latest file format");
    errno = 0;
    H5Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, untimed(H5P_FILE_CREATE).get(), fapl.get()), H5Fclose);
    w.check(file.valid(), "create the file");
    H5Handle root_group(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose);
    w.check(root_group.valid(), "open the root group");
    const hid_t root = root_group.get();
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

    H5Handle state(H5Gcreate2(root, "state", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
    w.check(state.valid(), "create group /state");
    w.rows(state.get(), "positions", s.x);
    w.rows(state.get(), "velocities", s.v);
    w.rows(state.get(), "accelerations", s.a);
    w.rows(state.get(), "internal_forces", s.f_int);
    w.rows(state.get(), "external_forces", s.f_ext);
    w.rows(state.get(), "reactions", s.reaction);
    if (!s.rigid.empty()) {
      std::vector<Vec3> rows;
      for (const RigidBodyState& b : s.rigid) rigid_rows(b, rows);
      w.rows(state.get(), "rigid_bodies", rows);
    }

    H5Handle ledger(H5Gcreate2(root, "ledger", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
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

    if (s.fracture) {
      const FractureState& f = *s.fracture;
      H5Handle group(H5Gcreate2(root, "fracture", H5P_DEFAULT, untimed(H5P_GROUP_CREATE).get(), H5P_DEFAULT), H5Gclose);
      w.check(group.valid(), "create group /fracture");
      const hid_t fr = group.get();
      w.integer(fr, "nodes", static_cast<long>(f.reference.size()));
      w.integer(fr, "facets", static_cast<long>(f.facet_state.size()));
      w.integer(fr, "cohesive_elements", static_cast<long>(f.cohesive_facet_gid.size()));
      w.attribute(fr, "mesh_revision", H5T_NATIVE_UINT64, &f.mesh_revision);
      w.rows(fr, "reference", f.reference);
      w.array(fr, "node_gid", f.node_gid);
      w.array(fr, "node_body", f.node_body);
      w.array(fr, "conn", f.conn, model.mesh.nodes_per_element());
      w.array(fr, "mass", f.mass);
      w.array(fr, "bc_mask", f.bc_mask);
      w.rows(fr, "bc_velocity", f.bc_velocity);
      w.array(fr, "bc_condition", f.bc_condition, 3);
      w.rows(fr, "initial_velocity", f.initial_velocity);
      w.array(fr, "facet_gid", f.facet_gid);
      w.array(fr, "facet_state", f.facet_state);
      const CohesiveElements& c = f.cohesive;
      w.array(fr, "cohesive_facet", f.cohesive_facet_gid);
      w.array(fr, "cohesive_side_local", c.side_local, kCohesiveSlots);
      w.array(fr, "cohesive_side_nodes", c.side_nodes, kCohesiveSlots);
      w.array(fr, "cohesive_area", c.area);
      w.rows(fr, "cohesive_normal", c.normal);
      w.array(fr, "cohesive_delta_max", c.delta_max, kCohesivePoints);
    }
    // Last: the sum of everything written above (not itself part of it).
    const std::uint64_t whole = w.digest.sum;
    w.attribute(root, "state_fnv1a64", H5T_NATIVE_UINT64, &whole);
    errno = 0;
    w.check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL) >= 0, "flush the file");
    // Closed here (the handles above): everything is in the OS's hands.
  } catch (const Error&) {
    // The half-written file is of no use, and its space lets the other
    // files close on a full disk (disk_reserve.hpp).
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
  sync_path(tmp, O_RDONLY);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  SHATTER_REQUIRE(!ec, "checkpoint: cannot rename " << tmp.string() << " to " << path.string()
                                                    << ": " << ec.message());
  const std::filesystem::path dir =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  sync_path(dir, O_RDONLY | O_DIRECTORY);
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

/// A part's share of a checkpoint's fracture state (docs/parallel.md "Fracture
/// on parts"), read block by block: the conn rows of its elements, the rows of
/// their nodes, and the facets and cohesive elements of facets one of whose
/// elements it holds (FractureStage::restore keeps those it holds both of).
void read_fracture_part(const Reader& r, hid_t fr, const Model& model, std::size_t elements, std::size_t facets,
                        FractureState& f) {
  const auto n = static_cast<std::size_t>(f.whole_nodes), nc = static_cast<std::size_t>(f.whole_cohesive);
  const int k = model.mesh.nodes_per_element();
  f.conn = r.array<Index>(fr, "conn", elements, k, model.part.element_index);
  f.node_rows = f.conn;
  std::sort(f.node_rows.begin(), f.node_rows.end());
  f.node_rows.erase(std::unique(f.node_rows.begin(), f.node_rows.end()), f.node_rows.end());
  r.require(f.node_rows.empty() || (f.node_rows.front() >= 0 && static_cast<std::size_t>(f.node_rows.back()) < n),
            "/fracture/conn names a node out of range (corrupted checkpoint?)");
  const std::span<const Index> rows = f.node_rows;
  f.reference = r.rows(fr, "reference", n, rows);
  f.node_gid = r.array<GlobalId>(fr, "node_gid", n, 1, rows);
  f.node_body = r.array<int>(fr, "node_body", n, 1, rows);
  f.mass = r.array<double>(fr, "mass", n, 1, rows);
  // The bc mask of the rows, and each prescribed row's rank among the whole model's.
  std::size_t next = 0;
  r.blocks<std::uint8_t>(fr, "bc_mask", n, 1, [&](std::size_t first, std::span<const std::uint8_t> block) {
    for (std::size_t i = 0; i < block.size(); ++i) {
      const bool kept = next < rows.size() && static_cast<std::size_t>(rows[next]) == first + i;
      if (kept) {
        f.bc_mask.push_back(block[i]);
        if (block[i]) f.bc_rows.push_back(f.whole_bc_nodes);
        ++next;
      }
      f.whole_bc_nodes += block[i] != 0;
    }
  });
  f.bc_velocity = r.rows(fr, "bc_velocity", n, rows);
  f.bc_condition = r.array<std::array<std::int32_t, 3>>(fr, "bc_condition", n, 3, rows);
  f.initial_velocity = r.rows(fr, "initial_velocity", n, rows);
  // Facets by global id, 4 g + face with g the smaller element's: those of the part's elements.
  std::vector<GlobalId> held(model.mesh.elem_gid.begin(), model.mesh.elem_gid.end());
  std::sort(held.begin(), held.end());
  auto of_part = [&](GlobalId facet) { return std::binary_search(held.begin(), held.end(), facet / 4); };
  // (Each dataset is read once: the whole file's digest counts every hash read.)
  auto picked = [&](const char* name, std::size_t count, std::vector<GlobalId>& gids) {
    std::vector<Index> keep;
    r.blocks<GlobalId>(fr, name, count, 1, [&](std::size_t first, std::span<const GlobalId> block) {
      for (std::size_t i = 0; i < block.size(); ++i)
        if (of_part(block[i])) {
          keep.push_back(static_cast<Index>(first + i));
          gids.push_back(block[i]);
        }
    });
    return keep;
  };
  const std::vector<Index> open = picked("facet_gid", facets, f.facet_gid);
  f.facet_state = r.array<FacetState>(fr, "facet_state", facets, 1, open);
  f.cohesive_whole = picked("cohesive_facet", nc, f.cohesive_facet_gid);
  const std::span<const Index> mine = f.cohesive_whole;
  CohesiveElements& c = f.cohesive;
  c.side_local = r.array<std::int8_t>(fr, "cohesive_side_local", nc, kCohesiveSlots, mine);
  c.side_nodes = r.array<Index>(fr, "cohesive_side_nodes", nc, kCohesiveSlots, mine);
  c.area = r.array<double>(fr, "cohesive_area", nc, 1, mine);
  c.normal = r.rows(fr, "cohesive_normal", nc, mine);
  c.delta_max = r.array<double>(fr, "cohesive_delta_max", nc, kCohesivePoints, mine);
}

}  // namespace

SimulationState read_checkpoint(const std::filesystem::path& path, const Model& model, CheckpointRun* run) {
  const Reader r{path.string(), {}};
  r.require(std::filesystem::is_regular_file(path), "no such file");
  const QuietHdf5 quiet;
  r.require(H5Fis_hdf5(path.c_str()) > 0,
            "not a readable HDF5 file (truncated or corrupted checkpoint?)");
  // STRONG: closing the file closes whatever a corrupted file left open.
  H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  r.require(fapl.valid() && H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) >= 0,
            "HDF5 failed to set up");
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  r.require(file.valid(), "cannot open the HDF5 file (truncated or corrupted checkpoint?)");
  H5Handle root_group(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose);
  r.require(root_group.valid(), "cannot open the root group (truncated or corrupted checkpoint?)");
  const hid_t root = root_group.get();
  r.require(r.text(root, "format") == kFormat, "not a shatter checkpoint");
  const long version = r.integer(root, "version");
  r.require(version >= kOldestVersion && version <= kVersion,
            "checkpoint format version " + std::to_string(version) + ", this shatter reads " +
                std::to_string(kOldestVersion) + " to " + std::to_string(kVersion));
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
    H5Handle group(H5Gopen2(root, "fracture", H5P_DEFAULT), H5Gclose);
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
      read_fracture_part(r, fr, model, static_cast<std::size_t>(elements), static_cast<std::size_t>(facets), f);
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
  H5Handle state(H5Gopen2(root, "state", H5P_DEFAULT), H5Gclose);
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
    s.x = r.rows(state.get(), "positions", n, nodes);
    s.v = r.rows(state.get(), "velocities", n, nodes);
    s.a = r.rows(state.get(), "accelerations", n, nodes);
    s.f_int = r.rows(state.get(), "internal_forces", n, nodes);
    s.f_ext = r.rows(state.get(), "external_forces", n, nodes);
    s.reaction = r.rows(state.get(), "reactions", b, f ? std::span<const Index>(f->bc_rows) : model.part.bc_index);
  } else {
    for (std::uint8_t m : s.fracture ? s.fracture->bc_mask : model.bc_mask) b += m != 0;
    s.x = r.rows(state.get(), "positions", n);
    s.v = r.rows(state.get(), "velocities", n);
    s.a = r.rows(state.get(), "accelerations", n);
    s.f_int = r.rows(state.get(), "internal_forces", n);
    s.f_ext = r.rows(state.get(), "external_forces", n);
    s.reaction = r.rows(state.get(), "reactions", b);
  }

  H5Handle ledger(H5Gopen2(root, "ledger", H5P_DEFAULT), H5Gclose);
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
