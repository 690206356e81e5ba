#include "runtime/field_output.hpp"

#include <hdf5.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "kernels/error.hpp"
#include "runtime/hdf5_failure.hpp"
#include "runtime/hdf5_rows.hpp"

namespace shatter {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 rows are written as 3 packed doubles");

/// Wraps a freshly created identifier; throws naming `what` when HDF5 failed.
H5Id checked(hid_t id, herr_t (*close)(hid_t), const std::string& what) {
  SHATTER_REQUIRE(id >= 0, "fields output: " << hdf5_write_failure(what));
  return H5Id(id, close);
}

void check(herr_t status, const std::string& what) {
  SHATTER_REQUIRE(status >= 0, "fields output: " << hdf5_write_failure(what));
}

/// The shared write_rows (hdf5_rows.hpp), its failures named "fields output".
void write_rows(hid_t group, const char* name, hid_t mem_type, hid_t file_type, const void* data, const Rows& rows,
                hsize_t cols) {
  shatter::write_rows(group, name, mem_type, file_type, data, rows, cols, "fields output");
}

/// Rows of 6 in Voigt order xx yy zz yz xz xy, as XDMF's Tensor6 order xx xy xz yy yz zz.
std::vector<double> tensor6_rows(std::span<const double> voigt) {
  constexpr std::array<int, 6> tensor6_from_voigt{0, 5, 4, 1, 3, 2};
  std::vector<double> out(voigt.size());
  for (size_t i = 0; i + 6 <= voigt.size(); i += 6)
    for (int c = 0; c < 6; ++c) out[i + c] = voigt[i + tensor6_from_voigt[c]];
  return out;
}

/// Writes a scalar attribute (collective: every rank passes the same value).
void write_attribute(hid_t object, const char* name, hid_t type, const void* value) {
  errno = 0;
  H5Id space = checked(H5Screate(H5S_SCALAR), H5Sclose, "create a scalar space");
  H5Id attr = checked(H5Acreate2(object, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                      H5Aclose, std::string("create attribute ") + name);
  check(H5Awrite(attr.get(), type, value), std::string("write attribute ") + name);
}

/// What fields.xdmf needs to know about one written frame.
struct FrameRecord {
  int step;
  double time;
  int mesh;  ///< k of /mesh/<k>
  int order;
  long long nodes;
  long long elements;
  bool fragment;
  bool damage;
  long long triangles;       ///< shell triangles
  long long shell_vertices;  ///< shell control vertices
};

std::string step_group_name(int step) {
  char name[32];
  std::snprintf(name, sizeof name, "/step_%06d", step);
  return name;
}

/// One <DataItem> naming an HDF5 dataset of fields.h5.
void data_item(std::ostream& os, const std::string& dims, const char* number_type, int precision,
               const std::string& dataset) {
  os << "          <DataItem Dimensions=\"" << dims << "\" NumberType=\"" << number_type
     << "\" Precision=\"" << precision << "\" Format=\"HDF\">fields.h5:" << dataset
     << "</DataItem>\n";
}

void attribute(std::ostream& os, const char* name, const char* type, const char* center,
               const std::string& dims, const char* number_type, int precision,
               const std::string& dataset) {
  os << "        <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\""
     << center << "\">\n";
  data_item(os, dims, number_type, precision, dataset);
  os << "        </Attribute>\n";
}

/// The XDMF 3 index of all frames: a temporal collection of uniform grids.
std::string xdmf_text(const std::vector<FrameRecord>& frames) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "<?xml version=\"1.0\" ?>\n"
     << "<Xdmf Version=\"3.0\">\n"
     << "  <Domain>\n"
     << "    <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const FrameRecord& f : frames) {
    const std::string mesh = "/mesh/" + std::to_string(f.mesh);
    const std::string step = step_group_name(f.step);
    const std::string n = std::to_string(f.nodes), e = std::to_string(f.elements);
    const int k = f.order == 1 ? 4 : 10;
    // The points (n of them, named prefix + coordinates etc.) with their displacement and velocity.
    auto geometry_and_motion = [&](const std::string& n, const std::string& prefix) {
      os << "        <Geometry GeometryType=\"XYZ\">\n";
      data_item(os, n + " 3", "Float", 8, mesh + "/" + prefix + "coordinates");
      os << "        </Geometry>\n";
      attribute(os, "displacement", "Vector", "Node", n + " 3", "Float", 8, step + "/" + prefix + "displacement");
      attribute(os, "velocity", "Vector", "Node", n + " 3", "Float", 8, step + "/" + prefix + "velocity");
    };
    const bool shells = f.triangles > 0;
    if (shells)
      os << "      <Grid Name=\"" << step.substr(1) << "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
         << "        <Time Value=\"" << f.time << "\"/>\n";
    if (!shells || f.elements > 0) {
      os << "      <Grid Name=\"" << (shells ? std::string("solids") : step.substr(1)) << "\" GridType=\"Uniform\">\n";
      if (!shells) os << "        <Time Value=\"" << f.time << "\"/>\n";
      os << "        <Topology TopologyType=\"" << (f.order == 1 ? "Tetrahedron" : "Tetrahedron_10")
         << "\" NumberOfElements=\"" << e << "\">\n";
      data_item(os, e + " " + std::to_string(k), "Int", 8, mesh + "/topology");
      os << "        </Topology>\n";
      geometry_and_motion(n, "");
      attribute(os, "stress", "Tensor6", "Cell", e + " 6", "Float", 8, step + "/stress");
      attribute(os, "von_mises", "Scalar", "Cell", e, "Float", 8, step + "/von_mises");
      attribute(os, "body", "Scalar", "Cell", e, "Int", 4, step + "/body");
      if (f.fragment) attribute(os, "fragment", "Scalar", "Cell", e, "Int", 4, step + "/fragment");
      if (f.damage) attribute(os, "damage", "Scalar", "Cell", e, "Float", 8, step + "/damage");
      os << "      </Grid>\n";
    }
    if (shells) {
      const std::string t = std::to_string(f.triangles);
      os << "      <Grid Name=\"shells\" GridType=\"Uniform\">\n"
         << "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << t << "\">\n";
      data_item(os, t + " 3", "Int", 8, mesh + "/shell_topology");
      os << "        </Topology>\n";
      geometry_and_motion(std::to_string(f.shell_vertices), "shell_");
      attribute(os, "membrane_force", "Tensor6", "Cell", t + " 6", "Float", 8, step + "/shell_membrane_force");
      attribute(os, "bending_moment", "Tensor6", "Cell", t + " 6", "Float", 8, step + "/shell_bending_moment");
      attribute(os, "body", "Scalar", "Cell", t, "Int", 4, mesh + "/shell_body");
      os << "      </Grid>\n";
      os << "      </Grid>\n";
    }
  }
  os << "    </Grid>\n"
     << "  </Domain>\n"
     << "</Xdmf>\n";
  return os.str();
}

/// Writes `text` to `path` through a temporary file and a rename, so a reader
/// never sees a half-written index. Returns false on failure.
bool replace_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    if (!out.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

/// True on every rank when `ok` holds on every rank of `comm`.
bool all_ok(bool ok, MPI_Comm comm) {
  int local = ok ? 1 : 0, global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MIN, comm);
  return global == 1;
}

/// Throws on every rank when some rank failed: the failing rank with its own
/// message, the others with a pointer to it (STYLE.md "Errors").
void require_all(const std::string& local_error, MPI_Comm comm) {
  if (all_ok(local_error.empty(), comm)) return;
  if (!local_error.empty()) throw Error(local_error);
  throw Error("fields output: another rank failed (see its message)");
}

}  // namespace

struct FieldWriter::State {
  MPI_Comm comm;
  int rank = 0;
  std::filesystem::path xdmf_path;
  H5Id file;
  int mesh_count = 0;  ///< mesh groups written so far
  std::uint64_t mesh_revision = 0;
  int mesh_order = 0;
  long long mesh_nodes = -1, mesh_elements = -1, mesh_triangles = 0, mesh_shell_vertices = 0;
  std::vector<FrameRecord> frames;

  void write_frame(const Mesh& mesh, const FieldFrame& frame);

  /// `e`'s message with the path of fields.h5 after "fields output".
  Error naming_the_file(const Error& e) const {
    std::string m = e.what();
    const std::string prefix = "fields output: ";
    if (m.rfind(prefix, 0) == 0) m = "fields output " + (xdmf_path.parent_path() / "fields.h5").string() + ": " + m.substr(prefix.size());
    return Error(m);
  }

  void write_xdmf() {
    std::string error;
    if (rank == 0 && !replace_file(xdmf_path, xdmf_text(frames)))
      error = "fields output: cannot write " + xdmf_path.string();
    require_all(error, comm);
  }
};

FieldWriter::FieldWriter(const std::filesystem::path& dir, MPI_Comm comm)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.comm = comm;
  MPI_Comm_rank(comm, &s.rank);
  s.xdmf_path = dir / "fields.xdmf";
  const std::filesystem::path h5_path = dir / "fields.h5";

  std::string error;
  if (s.rank == 0) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) error = "fields output: cannot create directory " + dir.string() + ": " + ec.message();
  }
  require_all(error, comm);

  const QuietHdf5 quiet;
  const H5Id fapl = mpio_access(comm, "fields output");
  errno = 0;
  s.file = H5Id(H5Fcreate(h5_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose);
  if (!all_ok(s.file.valid(), comm))
    throw Error("fields output " + h5_path.string() + ": " + hdf5_write_failure("create the file"));
  checked(H5Gcreate2(s.file.get(), "/mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
          "create group /mesh");
  // An index without frames replaces any stale one from an earlier run.
  s.write_xdmf();
}

FieldWriter::~FieldWriter() {
  if (!state_->file.valid()) return;
  // A close whose metadata flush fails leaves HDF5 a freed file to close
  // again at MPI_Finalize (hdf5_failure.hpp): flush first, and on failure
  // give the disk reserve back so that the close finds room.
  const QuietHdf5 quiet;
  if (H5Fflush(state_->file.get(), H5F_SCOPE_GLOBAL) < 0) release_disk_space();
  state_->file.reset();
}

void FieldWriter::write(const Mesh& mesh, const FieldFrame& frame) {
  const QuietHdf5 quiet;
  try {
    state_->write_frame(mesh, frame);
  } catch (const Error& e) {
    throw state_->naming_the_file(e);
  }
}

void FieldWriter::State::write_frame(const Mesh& mesh, const FieldFrame& frame) {
  State& s = *this;
  const size_t n = static_cast<size_t>(mesh.num_nodes());
  const size_t e = static_cast<size_t>(mesh.num_elements());

  // Optional fields are written when any rank has them; then every rank
  // passes them (a rank without elements passes empty spans).
  const std::array<int, 2> has_local{!frame.fragment.empty(), !frame.damage.empty()};
  std::array<int, 2> has{0, 0};
  MPI_Allreduce(has_local.data(), has.data(), 2, MPI_INT, MPI_MAX, s.comm);
  // Likewise the element order: a rank without elements may pass a default Mesh.
  const int local_order = e > 0 ? mesh.order : 1;
  int order = 1;
  MPI_Allreduce(&local_order, &order, 1, MPI_INT, MPI_MAX, s.comm);
  const size_t k = order == 1 ? 4 : 10;  // topology columns

  std::ostringstream error;
  auto expect_size = [&](const char* name, size_t size, size_t want) {
    if (size != want && error.str().empty())
      error << "fields output, step " << frame.step << ": " << name << " has " << size
            << " entries, expected " << want;
  };
  if (e > 0 && mesh.order != order)
    error << "fields output, step " << frame.step << ": mesh order " << mesh.order
          << " on this rank, " << order << " on another";
  expect_size("mesh.conn", mesh.conn.size(), e * k);
  expect_size("displacement", frame.displacement.size(), n);
  expect_size("velocity", frame.velocity.size(), n);
  expect_size("stress", frame.stress.size(), 6 * e);
  expect_size("von_mises", frame.von_mises.size(), e);
  expect_size("body", frame.body.size(), e);
  if (has[0]) expect_size("fragment", frame.fragment.size(), e);
  if (has[1]) expect_size("damage", frame.damage.size(), e);
  const ShellFrame no_shells;
  const ShellFrame& sh = frame.shells ? *frame.shells : no_shells;
  expect_size("shell_body", sh.body.size(), sh.triangles.size());
  expect_size("shell_displacement", sh.displacement.size(), sh.reference.size());
  expect_size("shell_velocity", sh.velocity.size(), sh.reference.size());
  expect_size("shell_membrane_force", sh.membrane_force.size(), 6 * sh.triangles.size());
  expect_size("shell_bending_moment", sh.bending_moment.size(), 6 * sh.triangles.size());
  require_all(error.str(), s.comm);

  // Global placement: [0] nodes, [1] elements, [2] shell vertices, [3] shell triangles.
  const std::array<long long, 4> local{static_cast<long long>(n), static_cast<long long>(e),
                                       static_cast<long long>(sh.reference.size()),
                                       static_cast<long long>(sh.triangles.size())};
  std::array<long long, 4> offset{0, 0, 0, 0}, total{0, 0, 0, 0};
  MPI_Exscan(local.data(), offset.data(), 4, MPI_LONG_LONG, MPI_SUM, s.comm);
  if (s.rank == 0) offset = {0, 0, 0, 0};
  MPI_Allreduce(local.data(), total.data(), 4, MPI_LONG_LONG, MPI_SUM, s.comm);
  auto rows = [&](int i) {
    return Rows{static_cast<hsize_t>(local[i]), static_cast<hsize_t>(offset[i]), static_cast<hsize_t>(total[i])};
  };
  const Rows node_rows = rows(0), elem_rows = rows(1), vertex_rows = rows(2), triangle_rows = rows(3);

  const int changed_local = s.mesh_count == 0 || mesh.revision != s.mesh_revision ||
                            order != s.mesh_order || total[0] != s.mesh_nodes ||
                            total[1] != s.mesh_elements;
  int changed = 0;
  MPI_Allreduce(&changed_local, &changed, 1, MPI_INT, MPI_MAX, s.comm);
  // HDF5 1.10 cannot close a file whose flush failed (disk_reserve.hpp): a
  // frame the disk has no room for is not begun.
  if (s.rank == 0) {
    const auto nodes = static_cast<std::uintmax_t>(total[0]), elements = static_cast<std::uintmax_t>(total[1]);
    std::uintmax_t bytes = nodes * 6 * sizeof(double) + elements * (8 * sizeof(double) + 2 * sizeof(int));
    if (changed) bytes += nodes * 3 * sizeof(double) + elements * k * sizeof(std::int64_t);
    const std::string lacking = lacking_space(s.xdmf_path.parent_path(), bytes);
    if (!lacking.empty()) error << "fields output: step " << frame.step << " not written: " << lacking;
  }
  require_all(error.str(), s.comm);
  if (changed) {
    const std::string name = "/mesh/" + std::to_string(s.mesh_count);
    H5Id group = checked(H5Gcreate2(s.file.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT,
                                    H5P_DEFAULT),
                         H5Gclose, "create group " + name);
    write_rows(group.get(), "coordinates", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE,
               mesh.reference.data(), node_rows, 3);
    // Gmsh numbers the TET10 mid-edge nodes 8:(2,3) 9:(1,3); XDMF/VTK 8:(1,3) 9:(2,3).
    std::vector<std::int64_t> topology(mesh.conn.begin(), mesh.conn.end());
    if (order == 2)
      for (size_t i = 0; i < e; ++i) std::swap(topology[i * k + 8], topology[i * k + 9]);
    // A model of shells alone has no element datasets (fields.xdmf names none).
    if (total[1] > 0)
      write_rows(group.get(), "topology", H5T_NATIVE_INT64, H5T_STD_I64LE, topology.data(), elem_rows, k);
    if (total[3] > 0) {
      std::vector<std::int64_t> triangles;
      for (const auto& c : sh.triangles) triangles.insert(triangles.end(), c.begin(), c.end());
      write_rows(group.get(), "shell_coordinates", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, sh.reference.data(),
                 vertex_rows, 3);
      write_rows(group.get(), "shell_topology", H5T_NATIVE_INT64, H5T_STD_I64LE, triangles.data(), triangle_rows, 3);
      write_rows(group.get(), "shell_body", H5T_NATIVE_INT, H5T_STD_I32LE, sh.body.data(), triangle_rows, 0);
    }
    s.mesh_triangles = total[3];
    s.mesh_shell_vertices = total[2];
    s.mesh_revision = mesh.revision;
    s.mesh_order = order;
    s.mesh_nodes = total[0];
    s.mesh_elements = total[1];
    ++s.mesh_count;
  }

  const std::string name = step_group_name(frame.step);
  SHATTER_REQUIRE(H5Lexists(s.file.get(), name.c_str(), H5P_DEFAULT) == 0,
                  "fields output: step " << frame.step << " was already written to "
                                         << s.xdmf_path.parent_path() / "fields.h5");
  H5Id group = checked(H5Gcreate2(s.file.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT,
                                  H5P_DEFAULT),
                       H5Gclose, "create group " + name);
  const int mesh_index = s.mesh_count - 1;
  write_attribute(group.get(), "time", H5T_NATIVE_DOUBLE, &frame.time);
  write_attribute(group.get(), "step", H5T_NATIVE_INT, &frame.step);
  write_attribute(group.get(), "mesh", H5T_NATIVE_INT, &mesh_index);

  write_rows(group.get(), "displacement", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE,
             frame.displacement.data(), node_rows, 3);
  write_rows(group.get(), "velocity", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, frame.velocity.data(),
             node_rows, 3);
  if (total[3] > 0) {
    write_rows(group.get(), "shell_displacement", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, sh.displacement.data(),
               vertex_rows, 3);
    write_rows(group.get(), "shell_velocity", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, sh.velocity.data(),
               vertex_rows, 3);
    const std::vector<double> n = tensor6_rows(sh.membrane_force), m = tensor6_rows(sh.bending_moment);
    write_rows(group.get(), "shell_membrane_force", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, n.data(), triangle_rows, 6);
    write_rows(group.get(), "shell_bending_moment", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, m.data(), triangle_rows, 6);
  }
  if (total[1] > 0) {
    const std::vector<double> stress = tensor6_rows(frame.stress);
    write_rows(group.get(), "stress", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, stress.data(), elem_rows, 6);
    write_rows(group.get(), "von_mises", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, frame.von_mises.data(), elem_rows, 0);
    write_rows(group.get(), "body", H5T_NATIVE_INT, H5T_STD_I32LE, frame.body.data(), elem_rows, 0);
    if (has[0])
      write_rows(group.get(), "fragment", H5T_NATIVE_INT, H5T_STD_I32LE, frame.fragment.data(), elem_rows, 0);
    if (has[1])
      write_rows(group.get(), "damage", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, frame.damage.data(), elem_rows, 0);
  }
  group.reset();
  // The index may be opened while the run goes on: make the data it names durable first.
  check(H5Fflush(s.file.get(), H5F_SCOPE_GLOBAL), "flush fields.h5");

  s.frames.push_back(FrameRecord{frame.step, frame.time, mesh_index, s.mesh_order, total[0],
                                 total[1], has[0] != 0, has[1] != 0, s.mesh_triangles, s.mesh_shell_vertices});
  s.write_xdmf();
}

}  // namespace shatter
