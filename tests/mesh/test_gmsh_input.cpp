// Primitive shapes meshed through Gmsh: volumes, orders, node order, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "expect_close.hpp"
#include "kernels/error.hpp"
#include "kernels/tet10.hpp"
#include "mesh/gmsh_input.hpp"

using namespace shatter;

namespace {
double total_volume(const Mesh& m) {
  double v = 0;
  for (Index e = 0; e < m.num_elements(); ++e) v += element_reference_volume(m, e);
  return v;
}
}  // namespace

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
