// Surface loads on one face (kernels/surface_load.hpp): a flat face's
// resultant (pressure: -p times the area vector; traction: t times the area),
// the shares of a flat 6-node face (corners 0, mid-edge nodes a third), and
// a curved 6-node face against its area vector by the closed-surface
// identity (the resultant of a uniform pressure on a closed surface is 0).
#include <gtest/gtest.h>

#include "kernels/surface_load.hpp"

using namespace shatter;

namespace {

/// A flat triangle and its 6-node version (mid-edge nodes on the edges).
void flat_face(Vec3* x) {
  x[0] = Vec3(0.1, 0.2, 0.3), x[1] = Vec3(1.3, 0.4, 0.1), x[2] = Vec3(0.2, 0.9, 0.8);
  x[3] = 0.5 * (x[0] + x[1]), x[4] = 0.5 * (x[1] + x[2]), x[5] = 0.5 * (x[2] + x[0]);
}

}  // namespace

TEST(SurfaceLoad, FlatFaceResultants) {
  Vec3 x[6];
  flat_face(x);
  const Vec3 area = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]);
  const double p = 3.0e7;
  const Vec3 t(1.0e6, -2.0e6, 0.5e6);
  for (int nodes : {3, 6}) {
    Vec3 f[6];
    pressure_forces(x, nodes, p, f);
    Vec3 sum = Vec3::Zero();
    for (int a = 0; a < nodes; ++a) sum += f[a];
    EXPECT_LT((sum + p * area).norm(), 1e-14 * p * area.norm()) << nodes << " nodes";
    traction_forces(x, nodes, t, f);
    sum = Vec3::Zero();
    for (int a = 0; a < nodes; ++a) sum += f[a];
    EXPECT_LT((sum - area.norm() * t).norm(), 1e-14 * area.norm() * t.norm()) << nodes << " nodes";
    if (nodes == 6) {
      for (int a = 0; a < 6; ++a) {  // the 6-node face's shares: 0 at corners, 1/3 at mid-edge nodes
        EXPECT_LT((f[a] - (a < 3 ? 0.0 : area.norm() / 3) * t).norm(), 1e-14 * area.norm() * t.norm()) << a;
      }
    }
  }
}

// A tetrahedron with curved (quadratic) faces: its four outward 6-node
// faces close the surface, so the nodal pressure forces add up to zero at
// every node count, whatever the curvature.
TEST(SurfaceLoad, PressureOnAClosedCurvedSurfaceHasNoResultant) {
  const Vec3 c[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  // Mid-edge nodes pushed off the straight edges.
  auto mid = [&](int i, int j) { return Vec3(0.5 * (c[i] + c[j]) + 0.07 * Vec3(i + 1.0, j - 1.0, 0.5 * i * j)); };
  // Outward faces of the positive tetrahedron (corners a, b, c; mid-edges ab, bc, ca).
  const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  Vec3 sum = Vec3::Zero();
  for (const auto& f : faces) {
    const Vec3 x[6] = {c[f[0]], c[f[1]], c[f[2]], mid(std::min(f[0], f[1]), std::max(f[0], f[1])),
                       mid(std::min(f[1], f[2]), std::max(f[1], f[2])), mid(std::min(f[2], f[0]), std::max(f[2], f[0]))};
    Vec3 force[6];
    pressure_forces(x, 6, 1.0, force);
    for (const Vec3& g : force) sum += g;
  }
  EXPECT_LT(sum.norm(), 1e-14);
}
