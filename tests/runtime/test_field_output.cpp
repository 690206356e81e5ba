// fields.h5 + fields.xdmf: every DataItem of the index names a dataset of the
// declared type and dims, values round-trip, topology changes get a new mesh
// group, and R ranks writing their parts give the file of 1 rank writing all.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "mpi_environment.hpp"
#include "kernels/error.hpp"
#include "runtime/field_output.hpp"

namespace shatter {
namespace {

namespace fs = std::filesystem;

int comm_rank(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}
int comm_size(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_size(comm, &r);
  return r;
}

/// A fresh output directory under the build tree, shared by the ranks of comm.
fs::path fresh_dir(const std::string& name, MPI_Comm comm) {
  const fs::path dir = fs::path(SHATTER_BINARY_DIR) / "test_output" / "field_output" / name;
  if (comm_rank(comm) == 0) fs::remove_all(dir);
  MPI_Barrier(comm);
  return dir;
}

/// A chain of `m` TET4 elements (j, j+1, j+2, j+3) over m + 3 nodes; the writer
/// does not care about the shape, only about sizes and numbering.
Mesh chain_mesh(int m) {
  Mesh mesh;
  mesh.order = 1;
  for (int i = 0; i < m + 3; ++i) {
    mesh.reference.push_back(Vec3(0.1 * i, 0.01 * (i % 2), 0.02 * (i % 3)));
    mesh.node_gid.push_back(i + 1);
    mesh.node_body.push_back(0);
  }
  for (int j = 0; j < m; ++j) {
    for (int a = 0; a < 4; ++a) mesh.conn.push_back(j + a);
    mesh.elem_gid.push_back(j + 1);
    mesh.elem_body.push_back(j % 2);
    mesh.elem_material.push_back(0);
  }
  return mesh;
}

/// One TET10 on the unit tetrahedron, Gmsh node order, conn = 0..9.
Mesh tet10_mesh() {
  Mesh mesh;
  mesh.order = 2;
  const Vec3 v[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
  for (const Vec3& x : v) mesh.reference.push_back(x);
  for (const auto& ed : edges) mesh.reference.push_back(0.5 * (v[ed[0]] + v[ed[1]]));
  for (int i = 0; i < 10; ++i) {
    mesh.node_gid.push_back(i + 1);
    mesh.node_body.push_back(0);
    mesh.conn.push_back(i);
  }
  mesh.elem_gid = {1};
  mesh.elem_body = {0};
  mesh.elem_material = {0};
  return mesh;
}

/// Field values of one frame, distinct per step, row and component.
struct FrameData {
  std::vector<Vec3> displacement, velocity;
  std::vector<double> stress, von_mises, damage;
  std::vector<int> body, fragment;

  FrameData(int nodes, int elements, int step, bool fracture) {
    for (int i = 0; i < nodes; ++i) {
      displacement.push_back(Vec3(1e-3 * step + i, 2.0 * i, -0.5 * i));
      velocity.push_back(Vec3(10.0 * step, i + 0.25, 3.0));
    }
    for (int e = 0; e < elements; ++e) {
      for (int c = 0; c < 6; ++c) stress.push_back(1e6 * step + 10.0 * e + c);
      von_mises.push_back(2e6 + e);
      body.push_back(e % 2);
      if (fracture) {
        fragment.push_back(e / 2);
        damage.push_back(0.125 * (e % 8));
      }
    }
  }
  /// The rows [node_begin, node_end) and [elem_begin, elem_end) as a frame.
  FieldFrame view(int step, double time, int node_begin, int node_end, int elem_begin,
                  int elem_end) const {
    const auto nodes = [&](const auto& v) {
      return std::span(v).subspan(node_begin, node_end - node_begin);
    };
    const auto elems = [&](const auto& v, int width) {
      return v.empty() ? std::span<const typename std::decay_t<decltype(v)>::value_type>()
                       : std::span(v).subspan(width * elem_begin, width * (elem_end - elem_begin));
    };
    return FieldFrame{step,           time,
                      nodes(displacement), nodes(velocity),
                      elems(stress, 6), elems(von_mises, 1),
                      elems(body, 1),   elems(fragment, 1),
                      elems(damage, 1)};
  }
  FieldFrame view(int step, double time) const {
    return view(step, time, 0, static_cast<int>(displacement.size()), 0,
                static_cast<int>(body.size()));
  }
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Serial read access to fields.h5 (after the writer closed it).
class H5Reader {
 public:
  explicit H5Reader(const fs::path& path)
      : file_(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~H5Reader() {
    if (file_ >= 0) H5Fclose(file_);
  }
  bool ok() const { return file_ >= 0; }
  bool exists(const std::string& path) const {
    return H5Lexists(file_, path.c_str(), H5P_DEFAULT) > 0;
  }
  std::vector<hsize_t> dims(const std::string& path) const {
    const hid_t d = H5Dopen2(file_, path.c_str(), H5P_DEFAULT);
    const hid_t s = H5Dget_space(d);
    std::vector<hsize_t> out(H5Sget_simple_extent_ndims(s));
    H5Sget_simple_extent_dims(s, out.data(), nullptr);
    H5Sclose(s);
    H5Dclose(d);
    return out;
  }
  /// "Float 8" or "Int 4": the XDMF NumberType and Precision of a dataset.
  std::string number_type(const std::string& path) const {
    const hid_t d = H5Dopen2(file_, path.c_str(), H5P_DEFAULT);
    const hid_t t = H5Dget_type(d);
    std::string out = H5Tget_class(t) == H5T_FLOAT     ? "Float"
                      : H5Tget_class(t) == H5T_INTEGER ? "Int"
                                                       : "?";
    out += " " + std::to_string(H5Tget_size(t));
    H5Tclose(t);
    H5Dclose(d);
    return out;
  }
  template <class T>
  std::vector<T> read(const std::string& path, hid_t mem_type) const {
    size_t count = 1;
    for (hsize_t d : dims(path)) count *= d;
    std::vector<T> out(count);
    const hid_t d = H5Dopen2(file_, path.c_str(), H5P_DEFAULT);
    H5Dread(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Dclose(d);
    return out;
  }
  double time_of(const std::string& group) const {
    double t = -1.0;
    const hid_t a = H5Aopen_by_name(file_, group.c_str(), "time", H5P_DEFAULT, H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &t);
    H5Aclose(a);
    return t;
  }
  hid_t id() const { return file_; }

 private:
  hid_t file_;
};

/// One <DataItem> of fields.xdmf.
struct XdmfItem {
  std::vector<hsize_t> dims;
  std::string number_type;  ///< "Float 8", "Int 4", ...
  std::string dataset;      ///< path inside fields.h5
};

std::vector<XdmfItem> xdmf_items(const std::string& xdmf) {
  const std::regex item(
      R"re(<DataItem Dimensions="([0-9 ]+)" NumberType="(\w+)" Precision="(\d)" Format="HDF">fields\.h5:([^<]+)</DataItem>)re");
  std::vector<XdmfItem> out;
  for (auto it = std::sregex_iterator(xdmf.begin(), xdmf.end(), item); it != std::sregex_iterator();
       ++it) {
    XdmfItem x;
    std::istringstream dims((*it)[1].str());
    for (hsize_t d; dims >> d;) x.dims.push_back(d);
    x.number_type = (*it)[2].str() + " " + (*it)[3].str();
    x.dataset = (*it)[4].str();
    out.push_back(x);
  }
  return out;
}

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// Every DataItem names an existing dataset with exactly its dims and type.
void expect_index_matches_file(const fs::path& dir) {
  const std::string xdmf = read_text(dir / "fields.xdmf");
  const std::vector<XdmfItem> items = xdmf_items(xdmf);
  EXPECT_EQ(items.size(), count_of(xdmf, "<DataItem")) << "a DataItem the test cannot parse";
  H5Reader h5(dir / "fields.h5");
  ASSERT_TRUE(h5.ok());
  for (const XdmfItem& x : items) {
    ASSERT_TRUE(h5.exists(x.dataset)) << x.dataset;
    EXPECT_EQ(h5.dims(x.dataset), x.dims) << x.dataset;
    EXPECT_EQ(h5.number_type(x.dataset), x.number_type) << x.dataset;
  }
}

TEST(FieldOutput, Tet4FramesAndTopologyChange) {
  const fs::path dir = fresh_dir("tet4", MPI_COMM_SELF);
  Mesh mesh = chain_mesh(3);
  Mesh split = chain_mesh(3);
  // Fracture duplicated node 3 for element 2.
  split.revision = 1;
  split.reference.push_back(split.reference[3]);
  split.conn[2 * 4 + 1] = 6;
  const FrameData f0(6, 3, 0, true), f1(6, 3, 10, true), f2(7, 3, 20, true);
  {
    FieldWriter writer(dir, MPI_COMM_SELF);
    EXPECT_EQ(count_of(read_text(dir / "fields.xdmf"), "GridType=\"Uniform\""), 0u);
    writer.write(mesh, f0.view(0, 0.0));
    EXPECT_EQ(count_of(read_text(dir / "fields.xdmf"), "GridType=\"Uniform\""), 1u);
    writer.write(mesh, f1.view(10, 1.5e-6));
    writer.write(split, f2.view(20, 3.0e-6));
    EXPECT_EQ(count_of(read_text(dir / "fields.xdmf"), "GridType=\"Uniform\""), 3u);
  }
  expect_index_matches_file(dir);

  const std::string xdmf = read_text(dir / "fields.xdmf");
  EXPECT_NE(xdmf.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(count_of(xdmf, "TopologyType=\"Tetrahedron\""), 3u);
  EXPECT_EQ(count_of(xdmf, "/mesh/0/coordinates"), 2u);
  EXPECT_EQ(count_of(xdmf, "/mesh/1/coordinates"), 1u);
  EXPECT_EQ(count_of(xdmf, "Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\""), 3u);
  EXPECT_EQ(count_of(xdmf, "Name=\"stress\" AttributeType=\"Tensor6\" Center=\"Cell\""), 3u);
  EXPECT_EQ(count_of(xdmf, "Name=\"fragment\" AttributeType=\"Scalar\" Center=\"Cell\""), 3u);
  EXPECT_EQ(count_of(xdmf, "Name=\"damage\""), 3u);
  EXPECT_NE(xdmf.find("<Time Value=\"1.5e-06\"/>"), std::string::npos);

  H5Reader h5(dir / "fields.h5");
  EXPECT_FALSE(h5.exists("/mesh/2"));
  const auto x1 = h5.read<double>("/mesh/1/coordinates", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(x1.size(), 21u);
  for (int i = 0; i < 7; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(x1[3 * i + c], split.reference[i][c]);
  const auto t1 = h5.read<std::int64_t>("/mesh/1/topology", H5T_NATIVE_INT64);
  ASSERT_EQ(t1.size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(t1[i], split.conn[i]);

  const auto u = h5.read<double>("/step_000010/displacement", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(u.size(), 18u);
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(u[3 * i + c], f1.displacement[i][c]);
  const auto v = h5.read<double>("/step_000020/velocity", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(v.size(), 21u);
  EXPECT_EQ(v[3 * 6 + 1], f2.velocity[6][1]);
  // Voigt xx yy zz yz xz xy in, XDMF Tensor6 xx xy xz yy yz zz out.
  const auto s = h5.read<double>("/step_000010/stress", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(s.size(), 18u);
  const int from_voigt[6] = {0, 5, 4, 1, 3, 2};
  for (int e = 0; e < 3; ++e)
    for (int c = 0; c < 6; ++c) EXPECT_EQ(s[6 * e + c], f1.stress[6 * e + from_voigt[c]]);
  EXPECT_EQ(h5.read<int>("/step_000020/fragment", H5T_NATIVE_INT), f2.fragment);
  EXPECT_EQ(h5.read<int>("/step_000020/body", H5T_NATIVE_INT), f2.body);
  EXPECT_EQ(h5.read<double>("/step_000000/damage", H5T_NATIVE_DOUBLE), f0.damage);
  EXPECT_EQ(h5.read<double>("/step_000000/von_mises", H5T_NATIVE_DOUBLE), f0.von_mises);
  EXPECT_EQ(h5.time_of("/step_000010"), 1.5e-6);
}

TEST(FieldOutput, Tet10ColumnsInXdmfOrderAndNoFractureFields) {
  const fs::path dir = fresh_dir("tet10", MPI_COMM_SELF);
  const Mesh mesh = tet10_mesh();
  const FrameData f(10, 1, 0, false);
  {
    FieldWriter writer(dir, MPI_COMM_SELF);
    writer.write(mesh, f.view(0, 0.0));
    writer.write(mesh, f.view(5, 1e-7));
  }
  expect_index_matches_file(dir);
  const std::string xdmf = read_text(dir / "fields.xdmf");
  EXPECT_EQ(count_of(xdmf, "TopologyType=\"Tetrahedron_10\""), 2u);
  EXPECT_EQ(count_of(xdmf, "/mesh/0/topology"), 2u);
  EXPECT_EQ(count_of(xdmf, "fragment"), 0u);
  EXPECT_EQ(count_of(xdmf, "damage"), 0u);

  H5Reader h5(dir / "fields.h5");
  EXPECT_FALSE(h5.exists("/mesh/1"));
  EXPECT_FALSE(h5.exists("/step_000005/fragment"));
  const auto t = h5.read<std::int64_t>("/mesh/0/topology", H5T_NATIVE_INT64);
  EXPECT_EQ(t, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 9, 8}));
  // In XDMF order node 8 is the midpoint of edge (1,3), node 9 of (2,3).
  const auto x = h5.read<double>("/mesh/0/coordinates", H5T_NATIVE_DOUBLE);
  const auto node = [&](std::int64_t i) { return Vec3(x[3 * i], x[3 * i + 1], x[3 * i + 2]); };
  EXPECT_EQ(node(t[8]), 0.5 * (node(t[1]) + node(t[3])));
  EXPECT_EQ(node(t[9]), 0.5 * (node(t[2]) + node(t[3])));
}

TEST(FieldOutput, ErrorsNameThePath) {
  const fs::path dir = fresh_dir("errors", MPI_COMM_SELF);
  fs::create_directories(dir);
  std::ofstream(dir / "plain_file") << "not a directory\n";
  const fs::path bad = dir / "plain_file" / "out";
  try {
    FieldWriter writer(bad, MPI_COMM_SELF);
    FAIL() << "no error for " << bad;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
  }

  FieldWriter writer(dir / "ok", MPI_COMM_SELF);
  const Mesh mesh = chain_mesh(2);
  const FrameData wrong(4, 2, 0, false);  // 4 nodes for a mesh of 5
  EXPECT_THROW(writer.write(mesh, wrong.view(0, 0.0)), Error);
  const FrameData right(5, 2, 0, false);
  writer.write(mesh, right.view(0, 0.0));
  EXPECT_THROW(writer.write(mesh, right.view(0, 0.0)), Error);  // step 0 again
}

/// Names of all datasets in a file, in visiting order.
std::vector<std::string> dataset_names(hid_t file) {
  std::vector<std::string> names;
  H5Ovisit(
      file, H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t, const char* name, const H5O_info_t* info, void* out) -> herr_t {
        if (info->type == H5O_TYPE_DATASET)
          static_cast<std::vector<std::string>*>(out)->push_back(name);
        return 0;
      },
      &names);
  return names;
}

/// Bytes of a dataset in its file type.
std::vector<unsigned char> raw_bytes(hid_t file, const std::string& name) {
  const hid_t d = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hid_t t = H5Dget_type(d);
  const hid_t s = H5Dget_space(d);
  std::vector<unsigned char> out(H5Sget_simple_extent_npoints(s) * H5Tget_size(t));
  H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  H5Sclose(s);
  H5Tclose(t);
  H5Dclose(d);
  return out;
}

/// The run of the MPI test: 2 frames on a chain mesh, 1 after a node split,
/// 1 on a single TET10, each rank writing the contiguous rows
/// [begin(r), begin(r+1)) of every array. From 3 ranks on, the last rank has
/// no rows at all; a rank without elements leaves the Mesh order at default.
void write_run(const fs::path& dir, MPI_Comm comm) {
  const int rank = comm_rank(comm), size = comm_size(comm);
  const int parts = size >= 3 ? size - 1 : size;
  const auto begin = [&](int total, int r) { return total * std::min(r, parts) / parts; };
  const Mesh whole = chain_mesh(7);
  Mesh split = chain_mesh(7);
  split.revision = 1;
  split.reference.push_back(split.reference[5]);
  split.conn[4 * 4 + 1] = 10;
  const Mesh tet10 = tet10_mesh();
  FieldWriter writer(dir, comm);
  int step = 0;
  const std::array<const Mesh*, 4> frames{&whole, &whole, &split, &tet10};
  for (const Mesh* m : frames) {
    const int n = m->num_nodes(), e = m->num_elements();
    const int n0 = begin(n, rank), n1 = begin(n, rank + 1);
    const int e0 = begin(e, rank), e1 = begin(e, rank + 1);
    // This rank's rows; its connectivity keeps the output (global) numbering.
    Mesh part;
    if (e1 > e0) part.order = m->order;
    part.revision = m->revision;
    part.reference.assign(m->reference.begin() + n0, m->reference.begin() + n1);
    const int k = m->nodes_per_element();
    part.conn.assign(m->conn.begin() + k * e0, m->conn.begin() + k * e1);
    part.elem_gid.assign(m->elem_gid.begin() + e0, m->elem_gid.begin() + e1);
    const FrameData f(n, e, step, true);
    writer.write(part, f.view(step, 1e-6 * step, n0, n1, e0, e1));
    step += 100;
  }
}

TEST(FieldOutputMpi, RankPartsGiveTheFileOfOneRank) {
  const int size = comm_size(MPI_COMM_WORLD);
  const std::string tag = "_np" + std::to_string(size);
  const fs::path whole = fresh_dir("mpi_whole" + tag, MPI_COMM_WORLD);
  const fs::path parts = fresh_dir("mpi_parts" + tag, MPI_COMM_WORLD);
  if (comm_rank(MPI_COMM_WORLD) == 0) write_run(whole, MPI_COMM_SELF);
  write_run(parts, MPI_COMM_WORLD);
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank(MPI_COMM_WORLD) != 0) return;

  expect_index_matches_file(parts);
  EXPECT_EQ(read_text(parts / "fields.xdmf"), read_text(whole / "fields.xdmf"));
  H5Reader a(whole / "fields.h5"), b(parts / "fields.h5");
  const std::vector<std::string> names = dataset_names(a.id());
  EXPECT_EQ(names.size(), 3u * 2 + 4u * 7);  // 3 meshes, 4 frames of 7 fields
  EXPECT_EQ(dataset_names(b.id()), names);
  for (const std::string& name : names) {
    EXPECT_EQ(b.dims(name), a.dims(name)) << name;
    EXPECT_EQ(b.number_type(name), a.number_type(name)) << name;
    EXPECT_TRUE(raw_bytes(b.id(), name) == raw_bytes(a.id(), name)) << name;
  }
  for (const char* step : {"/step_000000", "/step_000100", "/step_000200", "/step_000300"})
    EXPECT_EQ(b.time_of(step), a.time_of(step)) << step;
}

}  // namespace
}  // namespace shatter
