// Primitive shapes meshed through Gmsh: volumes, orders, node order, errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "expect_close.hpp"
#include "kernels/error.hpp"
#include "kernels/tet10.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/mesh_test_helpers.hpp"

using namespace shatter;
using shatter::test::input_error;
using shatter::test::total_volume;

TEST(GmshInput, BoxVolumeIsExactAndMeshValid) {
  ShapeSpec s;
  s.shape = "box";
  s.size = Vec3(1.0, 0.5, 0.25);
  s.center = Vec3(1, 2, 3);
  s.element_size = 0.1;
  const Mesh m = mesh_shape(s, 0, 0, "test");
  EXPECT_NO_THROW(validate_mesh(m, "test"));
  EXPECT_CLOSE(total_volume(m), 0.125, 1e-12, 0);
  EXPECT_GT(m.num_elements(), 100);
}

TEST(GmshInput, CylinderTet10VolumeConverges) {
  ShapeSpec s;
  s.shape = "cylinder";
  s.radius = 0.5;
  s.length = 2.0;
  s.axis = Vec3(1, 0, 0);
  s.element_size = 0.25;
  s.order = 2;
  const Mesh m = mesh_shape(s, 1, 0, "test");
  EXPECT_EQ(m.order, 2);
  EXPECT_NO_THROW(validate_mesh(m, "test"));
  // curved quadratic boundary: volume within 0.1 % of pi r^2 L at h = r/2
  EXPECT_CLOSE(total_volume(m), std::numbers::pi * 0.25 * 2.0, 1e-3, 0);
  // Gmsh's TET10 node order: node 4+e is the midpoint of edge kTet10Edges[e]
  // (exact for interior elements whose edges are straight).
  int straight = 0;
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Index* c = m.element(e);
    bool all = true;
    for (int k = 0; k < 6; ++k) {
      const Vec3 mid = 0.5 * (m.reference[c[kTet10Edges[k][0]]] + m.reference[c[kTet10Edges[k][1]]]);
      all = all && (mid - m.reference[c[4 + k]]).norm() < 1e-12;
    }
    straight += all;
  }
  EXPECT_GT(straight, m.num_elements() / 4);
  for (int b : m.elem_body) EXPECT_EQ(b, 1);
}

TEST(GmshInput, SphereTubeAndHollowSphereVolumes) {
  ShapeSpec s;
  s.shape = "sphere";
  s.radius = 1.0;
  s.element_size = 0.2;
  EXPECT_CLOSE(total_volume(mesh_shape(s, 0, 0, "t")), 4.0 / 3.0 * std::numbers::pi, 0.02, 0);
  ShapeSpec t;
  t.shape = "tube";
  t.inner_radius = 0.8;
  t.outer_radius = 1.0;
  t.length = 0.5;
  t.element_size = 0.1;
  EXPECT_CLOSE(total_volume(mesh_shape(t, 0, 0, "t")), std::numbers::pi * (1.0 - 0.64) * 0.5, 0.02, 0);
  // Hollow sphere (sphere minus sphere): the shell volume, and no node inside the cavity.
  ShapeSpec h = s;
  h.inner_radius = 0.8;
  h.element_size = 0.1;
  const Mesh hm = mesh_shape(h, 0, 0, "t");
  EXPECT_CLOSE(total_volume(hm), 4.0 / 3.0 * std::numbers::pi * (1.0 - 0.512), 0.02, 0);
  for (const Vec3& x : hm.reference) EXPECT_GT(x.norm(), 0.8 * (1 - 1e-3));
}

TEST(GmshInput, MshFileRoundTripV2AndV4) {
  // Write a two-tet mesh in both formats by hand and read it back.
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_msh_test";
  std::filesystem::create_directories(dir);
  const std::string v2 = (dir / "two.msh").string();
  {
    std::ofstream f(v2);
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0 0 -1\n$EndNodes\n"
         "$Elements\n2\n1 4 2 1 1 1 2 3 4\n2 4 2 1 1 1 3 2 5\n$EndElements\n";
  }
  const Mesh m = read_msh(v2, "", 0, 0, "bodies[0].mesh.file");
  EXPECT_EQ(m.num_elements(), 2);
  EXPECT_EQ(m.num_nodes(), 5);
  EXPECT_NO_THROW(validate_mesh(m, "t"));
  EXPECT_CLOSE(total_volume(m), 2.0 / 6.0, 1e-14, 0);
  const std::string v4 = (dir / "two_v4.msh").string();
  {
    std::ofstream f(v4);
    f << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 -1 -1 -1 1 1 1 0 0\n$EndEntities\n"
         "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 -1\n$EndNodes\n"
         "$Elements\n1 2 1 2\n3 1 4 2\n1 1 2 3 4\n2 1 3 2 5\n$EndElements\n";
  }
  const Mesh m4 = read_msh(v4, "", 0, 0, "t");
  EXPECT_EQ(m4.num_elements(), 2);
  EXPECT_CLOSE(total_volume(m4), 2.0 / 6.0, 1e-14, 0);
}

TEST(GmshInput, BadMeshesAreRejectedWithTheElementId) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_msh_test";
  std::filesystem::create_directories(dir);
  const std::string inv = (dir / "inverted.msh").string();
  {
    std::ofstream f(inv);  // element 2 has negative volume
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0 0 -1\n$EndNodes\n"
         "$Elements\n2\n1 4 2 1 1 1 2 3 4\n7 4 2 1 1 2 3 1 5\n$EndElements\n";
  }
  Mesh m = read_msh(inv, "", 0, 0, "t");
  try {
    validate_mesh(m, "beam.msh");
    FAIL() << "inverted element accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("element 7 is inverted"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("beam.msh"), std::string::npos) << e.what();
  }
  // unused node
  const std::string good = (dir / "good.msh").string();
  {
    std::ofstream f(good);
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
         "$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n";
  }
  m = read_msh(good, "", 0, 0, "t");
  EXPECT_NO_THROW(validate_mesh(m, "t"));
  m.reference.push_back(Vec3(5, 5, 5));
  m.node_gid.push_back(99);
  m.node_body.push_back(0);
  try {
    validate_mesh(m, "t");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 99"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_msh((dir / "missing.msh").string(), "", 0, 0, "t"), InputError);
  const std::string junk = (dir / "junk.msh").string();
  std::ofstream(junk) << "this is not a mesh\n";
  EXPECT_THROW(read_msh(junk, "", 0, 0, "t"), InputError);
}

namespace {

// Hand-written .msh files in the four layouts read_msh accepts, so that the
// scan of their $Elements (scan_msh_elements) is checked against Gmsh's own
// reading of the same bytes.
struct MshElem {
  int type;                ///< 4 (TET4) or 11 (TET10)
  std::vector<int> nodes;  ///< node tags
};

struct MshLayout {
  const char* name;
  bool v41, binary, swap;
};

constexpr MshLayout kLayouts[] = {{"v22_ascii", false, false, false},
                                  {"v22_binary", false, true, false},
                                  {"v22_binary_swapped", false, true, true},
                                  {"v41_ascii", true, false, false},
                                  {"v41_binary", true, true, false},
                                  {"v41_binary_swapped", true, true, true}};

class MshWriter {
 public:
  explicit MshWriter(const MshLayout& l) : l_(l) {}

  std::string file(const std::vector<Vec3>& nodes, const std::vector<MshElem>& elems) {
    const size_t nn = nodes.size(), ne = elems.size();
    out_ << "$MeshFormat\n" << (l_.v41 ? "4.1" : "2.2") << (l_.binary ? " 1 8\n" : " 0 8\n");
    if (l_.binary) put<std::int32_t>(1), out_ << "\n";
    out_ << "$EndMeshFormat\n";
    if (l_.v41) {
      // One volume (tag 1) without physical groups or bounding surfaces.
      out_ << "$Entities\n";
      for (size_t c : {0, 0, 0, 1}) size(c);
      end_line();
      integer(1);
      for (double b : {-1, -1, -1, 1, 1, 1}) real(b);
      size(0), size(0), end_line();
      end_line("$EndEntities\n$Nodes\n");
      size(1), size(nn), size(1), size(nn), end_line();
      integer(3), integer(1), integer(0), size(nn), end_line();
      for (size_t i = 0; i < nn; ++i) size(i + 1), end_line();
      for (const Vec3& x : nodes) real(x.x()), real(x.y()), real(x.z()), end_line();
      end_line("$EndNodes\n$Elements\n");
      // One block per run of elements of one type.
      std::vector<std::pair<size_t, size_t>> blocks;  // first, count
      for (size_t e = 0; e < ne; ++e)
        if (e == 0 || elems[e].type != elems[e - 1].type) blocks.push_back({e, 1});
        else ++blocks.back().second;
      size(blocks.size()), size(ne), size(1), size(ne), end_line();
      for (const auto& [first, count] : blocks) {
        integer(3), integer(1), integer(elems[first].type), size(count), end_line();
        for (size_t e = first; e < first + count; ++e) {
          size(e + 1);
          for (int n : elems[e].nodes) size(n);
          end_line();
        }
      }
    } else {
      out_ << "$Nodes\n" << nn << "\n";
      for (size_t i = 0; i < nn; ++i)
        integer(int(i + 1)), real(nodes[i].x()), real(nodes[i].y()), real(nodes[i].z()), end_line();
      end_line("$EndNodes\n$Elements\n");
      out_ << ne << "\n";
      for (size_t e = 0; e < ne; ++e) {
        // Binary: a block header (type, 1 element, 2 tags) per element.
        if (l_.binary) put<std::int32_t>(elems[e].type), put<std::int32_t>(1), put<std::int32_t>(2);
        integer(int(e + 1));
        if (!l_.binary) integer(elems[e].type), integer(2);
        integer(1), integer(1);  // physical and elementary tags
        for (int n : elems[e].nodes) integer(n);
        end_line();
      }
    }
    end_line("$EndElements\n");
    return out_.str();
  }

 private:
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (l_.swap) std::reverse(b, b + sizeof(T));
    out_.write(b, sizeof(T));
  }
  void integer(int v) { l_.binary ? put<std::int32_t>(v) : void(out_ << v << ' '); }
  void size(size_t v) { l_.binary ? put<std::uint64_t>(v) : void(out_ << v << ' '); }
  void real(double v) { l_.binary ? put<double>(v) : void(out_ << v << ' '); }
  /// Ends a line of data (ASCII), or starts the lines `then` (binary data
  /// has no lines; the text after it starts on a new one).
  void end_line(const char* then = "") {
    if (l_.binary == (*then != 0)) out_ << "\n";
    out_ << then;
  }

  MshLayout l_;
  std::ostringstream out_;
};

/// Two tets sharing a face (volume 1/6 each), as TET4 or TET10; nodes 6-14
/// are the TET10 edge midpoints (Gmsh order, kTet10Edges).
std::vector<Vec3> two_tet_nodes(std::vector<MshElem>& tet4, std::vector<MshElem>& tet10) {
  std::vector<Vec3> x = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}};
  tet4 = {{4, {1, 2, 3, 4}}, {4, {1, 3, 2, 5}}};
  tet10.clear();
  for (const MshElem& t : tet4) {
    MshElem q{11, t.nodes};
    for (const auto& [a, b] : kTet10Edges) {
      x.push_back(0.5 * (x[t.nodes[a] - 1] + x[t.nodes[b] - 1]));
      q.nodes.push_back(int(x.size()));
    }
    tet10.push_back(q);
  }
  return x;
}

std::string write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}


}  // namespace

// Each layout, TET4 and TET10: the scan finds what Gmsh reads (read_msh
// succeeds with the exact volume); tets of both orders in one file are
// refused before Gmsh sees them, whichever comes first.
TEST(GmshInput, ScanFindsTheElementTypesAndRefusesMixedOrders) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_msh_scan";
  std::filesystem::create_directories(dir);
  std::vector<MshElem> tet4, tet10;
  const std::vector<Vec3> x = two_tet_nodes(tet4, tet10);
  for (const MshLayout& l : kLayouts) {
    SCOPED_TRACE(l.name);
    for (const auto& [elems, order] : {std::pair{tet4, 1}, std::pair{tet10, 2}}) {
      const std::string f = write_file(dir / (std::string(l.name) + "_o" + std::to_string(order) + ".msh"),
                                       MshWriter(l).file(x, elems));
      const std::vector<MshElementType> types = scan_msh_elements(f, "t");
      ASSERT_EQ(types.size(), 1u);
      EXPECT_EQ(types[0].type, elems[0].type);
      EXPECT_EQ(types[0].count, 2u);
      EXPECT_EQ(types[0].first_tag, 1u);
      EXPECT_TRUE(types[0].tetrahedron);
      const Mesh m = read_msh(f, "", 0, 0, "t");
      EXPECT_EQ(m.order, order);
      EXPECT_EQ(m.num_elements(), 2);
      EXPECT_CLOSE(total_volume(m), 2.0 / 6.0, 1e-14, 0);
    }
    for (const bool tet4_first : {true, false}) {
      const std::vector<MshElem> mixed = tet4_first ? std::vector{tet4[0], tet10[1]} : std::vector{tet10[0], tet4[1]};
      const std::string f = write_file(dir / (std::string(l.name) + "_mixed.msh"), MshWriter(l).file(x, mixed));
      const std::string why = input_error([&] { read_msh(f, "", 0, 0, "scene.yaml: bodies[2].mesh"); });
      EXPECT_EQ(why, "scene.yaml: bodies[2].mesh: '" + f + "' mixes " + (tet4_first ? "4- and 10" : "10- and 4") +
                         "-node tetrahedra (elements 1 and 2); expected tetrahedra of one order, 4- or 10-node");
    }
  }
}

// What the scan cannot follow is refused with the file and what was expected:
// other formats, files cut anywhere in a binary section, counts that run past
// the end, unknown element types.
TEST(GmshInput, ScanRefusesWhatItCannotFollow) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_msh_scan";
  std::filesystem::create_directories(dir);
  auto refusal = [&](const std::string& name, const std::string& bytes) {
    const std::string f = write_file(dir / name, bytes);
    return input_error([&] { scan_msh_elements(f, "w"); });
  };
  EXPECT_NE(refusal("text.msh", "a line of text\n").find("does not begin with $MeshFormat; expected a Gmsh .msh "
                                                          "file of format 2.2 or 4.1 (ASCII or binary)"),
            std::string::npos);
  EXPECT_NE(refusal("v40.msh", "$MeshFormat\n4 0 8\n$EndMeshFormat\n").find("is of .msh format 4; expected"),
            std::string::npos);
  std::vector<MshElem> tet4, tet10;
  const std::vector<Vec3> x = two_tet_nodes(tet4, tet10);
  for (const MshLayout& l : kLayouts) {
    if (!l.binary) continue;
    SCOPED_TRACE(l.name);
    const std::string whole = MshWriter(l).file(x, tet10);
    // Cut inside the nodes and inside the elements.
    for (const char* section : {"$Nodes\n", "$Elements\n"}) {
      const size_t at = whole.find(section) + std::strlen(section) + 20;
      const std::string why = refusal(std::string(l.name) + "_cut.msh", whole.substr(0, at));
      EXPECT_NE(why.find("is cut short or malformed in its " + std::string(section, std::strlen(section) - 1) +
                         " section"),
                std::string::npos)
          << why;
    }
  }
  // An element count far past the end of an ASCII file, and an unknown type.
  const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Elements\n";
  EXPECT_NE(refusal("count.msh", head + "1000000000000\n1 4 2 1 1 1 2 3 4\n$EndElements\n")
                .find("cut short or malformed in its $Elements section"),
            std::string::npos);
  EXPECT_NE(refusal("type.msh", head + "1\n9 777 0 1 2 3\n$EndElements\n")
                .find("holds element 9 of type 777, which is not a Gmsh element type"),
            std::string::npos);
}

// A node at NaN, inf or 1e200 was reported as an element "of zero volume"
// (the volume test overflowed or saw NaN): now the node is named, with where
// it is and the bound (issue 21).
TEST(GmshInput, NodesBeyondTheCoordinateBoundAreNamed) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_msh_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "far.msh").string();
  std::ofstream(path) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1e200\n"
                         "$EndNodes\n$Elements\n1\n5 4 2 1 1 1 2 3 4\n$EndElements\n";
  Mesh m = read_msh(path, "", 0, 0, "t");
  for (const double bad : {1e200, -2e9, std::nan(""), HUGE_VAL}) {
    for (Vec3& X : m.reference)
      if (X.z() != 0) X.z() = bad;
    try {
      validate_mesh(m, "far.msh");
      FAIL() << "a node at z = " << bad << " accepted";
    } catch (const InputError& e) {
      std::ostringstream z;
      z << bad;
      EXPECT_NE(std::string(e.what()).find("far.msh: node 4 of element 5 is at (0, 0, " + z.str() +
                                           "); expected finite coordinates within 1e+09 m of the origin"),
                std::string::npos)
          << e.what();
    }
  }
  // The unit tet moved to z = 1e9 - 1 ... 1e9: within the bound, and valid.
  for (Vec3& X : m.reference) X.z() = X.z() == 0 ? 1e9 - 1 : 1e9;
  EXPECT_NO_THROW(validate_mesh(m, "far.msh"));
}
