#pragma once
// Decomposition contact response (DCR) on one contact pair: Cirak & West,
// "Decomposition contact response (DCR) for explicit finite element
// dynamics", IJNME 64 (2005) 1078-1110 (below: [CW]).
//
// A pair is four surface nodes, the columns of a PairPoints matrix:
//   VertexFace: {p, a, b, c}   (triangle a-b-c counter-clockwise seen from outside)
//   EdgeEdge:   {a0, a1, b0, b1}
// The constraint is the signed volume of the tetrahedron of the four points
// ([CW] sec. 2.2), g = s V with
//   V(x) = (x1 - x0) . ((x2 - x0) x (x3 - x0)) / 6                      [m^3]
// and the orientation s chosen so that g > 0 is admissible: for a vertex and
// a face s = -1, i.e. g = ((b - a) x (c - a)) . (p - a) / 6 > 0 when p is on
// the outer side; for two edges s keeps edge b on the outer side of edge a, from
// the outward surface normals at their nodes (dcr_orientation).
// g is invariant under translations and rotations of the four points, so
// sum_i grad_i g = 0 and sum_i x_i x grad_i g = 0: impulses along grad g (and
// along the gradient of any such function) conserve linear and angular
// momentum exactly ([CW] sec. 3).
//
// Per pair and step, with positions moving linearly from X_old to X_new:
//   1. detection (dcr_detect): g(t) is a cubic in t; the pair penetrates when g
//      ends negative and the stretch of negative g began (g(t*) = 0) with the
//      vertex inside the triangle / the two segments crossing at t*;
//   2. projection (dcr_project): x_i += mu W_i grad_i g (W = M^-1, the inverse
//      lumped masses; W_i = 0 is a fixed node), mu > 0 the smallest root of
//      g(mu) = gap target (a cubic in mu), so the pair's centre of mass stays;
//   3. momentum decomposition (dcr_impulse), [CW] sec. 3-4: normal part
//      v_n = grad g . v / (grad g . W grad g), v' = v - (1 + e) v_n W grad g,
//      then Coulomb friction as a second decomposition along a slide direction;
//   dcr_resolve_pair places the collision at the end of the step (2 then 3, [CW]),
//   in the middle or at the contact time t* (3 there, 2 only for what is left).
// Pure functions: no allocation, no threads, no I/O.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>

#include "kernels/types.hpp"

namespace shatter {

/// The four points (columns, m) or velocities (m/s) of one contact pair.
using PairPoints = Eigen::Matrix<double, 3, 4>;
/// The outward surface normals of one pair at the start of the step (columns, any length,
/// 0 = none): VertexFace: the vertex's (columns 1-3 unused); EdgeEdge: edge a's and edge b's
/// (the sums of their triangles' normals), then the normal of edge a's triangle in which the
/// edge runs a0 -> a1 and that of edge b's in which it runs b0 -> b1 (0 unless the edge has
/// exactly two triangles, one each way: its other triangle's normal is the sum less this one).
using PairNormals = Eigen::Matrix<double, 3, 4>;
/// One value per node of a pair, e.g. the inverse lumped masses (1/kg; 0 = fixed node).
using PairWeights = Eigen::Vector4d;

/// W G for the inverse masses W of a pair's nodes: one per node (PairWeights), or one per
/// node and component (PairPoints: 0 in a component a condition holds, so that the
/// decompositions move the node only in its free components, as if its mass were infinite
/// in the held ones). Both give the same bits for the same per-node values.
template <class Derived>
PairPoints weighted(const PairPoints& G, const Eigen::MatrixBase<Derived>& w) {
  if constexpr (Derived::RowsAtCompileTime == 3) {
    return G.cwiseProduct(w.derived());
  } else {
    PairPoints D = G;
    for (int i = 0; i < 4; ++i) D.col(i) *= w[i];
    return D;
  }
}

/// The inverse mass of a pair whose nodes may belong to one free rigid body (a "mobility":
/// the velocity change of every node under impulses on the pair's nodes). The deformable
/// nodes as weighted() above (w, per node and component; its columns of the rigid nodes are
/// not read); the nodes with rigid[i] move with the body: impulses J_a on them give the body
/// dP = sum_a J_a, dL = sum_a r_a x J_a, hence node i the velocity change
///   D_i = dP / M + (J^-1 dL) x r_i,   r_i = x_i - c
/// (inv_mass = 1/M, inv_inertia = J^-1 in the world frame, r the nodes' arms). The mobility
/// is symmetric and positive: G . D = |sum G_a|^2 / M + (sum r_a x G_a) . J^-1 (sum r_a x G_a).
struct PairMobility {
  PairPoints w = PairPoints::Zero();  ///< deformable nodes: inverse mass per component, 1/kg
  std::array<bool, 4> rigid{};        ///< the node moves with the rigid body
  double inv_mass = 0;                ///< 1/M of the rigid body, 1/kg
  Mat3 inv_inertia = Mat3::Zero();    ///< J^-1 (world frame), 1/(kg m^2)
  PairPoints r = PairPoints::Zero();  ///< per rigid node: x_i - c, m
};

inline PairPoints weighted(const PairPoints& G, const PairMobility& m) {
  PairPoints D = G.cwiseProduct(m.w);
  Vec3 P = Vec3::Zero(), L = Vec3::Zero();
  for (int i = 0; i < 4; ++i)
    if (m.rigid[i]) P += G.col(i), L += m.r.col(i).cross(G.col(i));
  const Vec3 omega = m.inv_inertia * L;
  for (int i = 0; i < 4; ++i)
    if (m.rigid[i]) D.col(i) = m.inv_mass * P + omega.cross(m.r.col(i));
  return D;
}

enum class DcrPairKind : std::uint8_t { VertexFace = 0, EdgeEdge = 1 };

/// Where in the step dcr_resolve_pair places a collision (scene key contact.placement).
enum class DcrPlacement : std::uint8_t {
  End = 0,     ///< projection, then the impulse at the end of the step ([CW])
  Middle = 1,  ///< the impulse at the mid-step configuration
  Impact = 2,  ///< the impulse at the configuration of the contact time t*
};

/// Contact law of the DCR response.
struct DcrLaw {
  double restitution = 1.0;  ///< e in [0, 1]: 1 = elastic, 0 = perfectly plastic
  double friction = 0.0;     ///< Coulomb coefficient mu >= 0
  double gap = 1e-6;         ///< separation left after projection, as a fraction of the
                             ///< pair's longest edge (dimensionless)
  DcrPlacement placement = DcrPlacement::End;  ///< dcr_resolve_pair
};

/// A distance below kDcrTouchTolerance L (L the pair's longest edge) counts as touching:
/// |g| <= kDcrTouchTolerance L |n| / 6, with |n| from pair_normal_norm.
inline constexpr double kDcrTouchTolerance = 1e-11;
/// Barycentric / segment-parameter slack of the inside tests (dimensionless), so a
/// vertex crossing exactly on an edge shared by two triangles is caught by both.
inline constexpr double kDcrInsideTolerance = 1e-9;
/// Edges with sin^2(angle) below this are parallel: their volume vanishes
/// identically and the vertex-face pairs of their end points carry the contact.
inline constexpr double kDcrParallelTolerance = 1e-12;

/// V(X) = (x1 - x0) . ((x2 - x0) x (x3 - x0)) / 6, m^3.
inline double pair_volume(const PairPoints& X) {
  return (X.col(1) - X.col(0)).dot((X.col(2) - X.col(0)).cross(X.col(3) - X.col(0))) / 6.0;
}

/// Exact gradient of pair_volume, columns dV/dx_i (m^2):
///   dV/dx1 = e2 x e3 / 6, dV/dx2 = e3 x e1 / 6, dV/dx3 = e1 x e2 / 6,
///   dV/dx0 = -(dV/dx1 + dV/dx2 + dV/dx3),   e_k = x_k - x0.
inline PairPoints pair_volume_gradient(const PairPoints& X) {
  const Vec3 e1 = X.col(1) - X.col(0), e2 = X.col(2) - X.col(0), e3 = X.col(3) - X.col(0);
  PairPoints G;
  G.col(1) = e2.cross(e3) / 6.0;
  G.col(2) = e3.cross(e1) / 6.0;
  G.col(3) = e1.cross(e2) / 6.0;
  G.col(0) = -(G.col(1) + G.col(2) + G.col(3));
  return G;
}

/// Longest edge of the pair's primitives (the triangle, or the two edges), m.
inline double pair_length_scale(DcrPairKind kind, const PairPoints& X) {
  if (kind == DcrPairKind::VertexFace)
    return std::sqrt(std::max({(X.col(2) - X.col(1)).squaredNorm(), (X.col(3) - X.col(2)).squaredNorm(),
                               (X.col(1) - X.col(3)).squaredNorm()}));
  return std::sqrt(std::max((X.col(1) - X.col(0)).squaredNorm(), (X.col(3) - X.col(2)).squaredNorm()));
}

/// |n| of the primitives' normal n = (b - a) x (c - a) (VF) or (a1 - a0) x (b1 - b0)
/// (EE), m^2: the distance of the pair is 6 |g| / |n|.
inline double pair_normal_norm(DcrPairKind kind, const PairPoints& X) {
  if (kind == DcrPairKind::VertexFace) return (X.col(2) - X.col(1)).cross(X.col(3) - X.col(1)).norm();
  return (X.col(1) - X.col(0)).cross(X.col(3) - X.col(2)).norm();
}

/// The thickness of a pair with a shell among its sides (docs/shells.md "Contact"). A shell's
/// contact surface is its control mesh, the mid-surface's control net, thickened by its
/// half-thickness r: the points within r of it (both faces at +-r, rounded at the edges and
/// vertices). A pair of sides with r_1 and r_2 (0 for a solid) keeps its primitives h = r_1 + r_2
/// apart: its constraint is
///   g_h(X) = dist(X) - h  (m),
/// dist the distance between the vertex and the triangle (closest point on the triangle, its
/// interior, an edge or a corner) / between the two segments (closest points, clamped to the
/// segments). dist is invariant under translations and rotations of the four points, so its
/// gradient has zero net force and torque and the impulses along it keep both momenta
/// exactly, as the volume's do; no side is needed (a sheet has two outer faces).
struct PairThickness {
  double reach = 0.0;  ///< h = r_1 + r_2, m; 0: a pair of solids (the volume constraint)
};

/// The distance of a pair's primitives (m) and its gradient (columns, dimensionless): with
/// the closest points q_A = sum_i c_i x_i on the vertex / edge a and q_B = sum_j c_j x_j on the
/// face / edge b (c the barycentric or segment weights of the closest points, clamped to the
/// primitives) and u = (q_A - q_B) / |q_A - q_B|, d dist / d x_i = c_i u on side A and -c_j u
/// on side B (the closest point moves with the primitive; its motion along it is second
/// order). Zero gradient where the primitives meet (dist = 0).
struct PairDistance {
  double distance = 0.0;
  PairPoints gradient = PairPoints::Zero();
};

inline PairDistance pair_distance(DcrPairKind kind, const PairPoints& X) {
  PairWeights c = PairWeights::Zero();  // weights of the closest points: side A positive, side B negative
  if (kind == DcrPairKind::VertexFace) {
    // The closest point of the triangle to p: the face's interior if the projection lies in
    // it, else the closest point of the nearest edge.
    const Vec3 p = X.col(0), a = X.col(1), b = X.col(2), cc = X.col(3);
    const Vec3 e1 = b - a, e2 = cc - a, w = p - a;
    const Vec3 n = e1.cross(e2);
    const double nn = n.squaredNorm();
    double lb = -1, lc = -1;
    if (nn > 0) lb = w.cross(e2).dot(n) / nn, lc = e1.cross(w).dot(n) / nn;
    std::array<double, 3> l{};
    if (nn > 0 && lb >= 0 && lc >= 0 && lb + lc <= 1) {
      l = {1 - lb - lc, lb, lc};
    } else {
      double best = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const int i = k, j = (k + 1) % 3;
        const Vec3 u = X.col(1 + j) - X.col(1 + i);
        const double uu = u.squaredNorm();
        const double s = uu > 0 ? std::clamp((p - X.col(1 + i)).dot(u) / uu, 0.0, 1.0) : 0.0;
        const double d2 = (p - X.col(1 + i) - s * u).squaredNorm();
        if (d2 < best) {
          best = d2;
          l = {0, 0, 0};
          l[i] = 1 - s;
          l[j] = s;
        }
      }
    }
    c << 1.0, -l[0], -l[1], -l[2];
  } else {
    // Closest points of the segments a0 + sa ea, b0 + sb eb, sa, sb in [0, 1]: the lines'
    // closest points clamped, each re-projected on the other segment.
    const Vec3 ea = X.col(1) - X.col(0), eb = X.col(3) - X.col(2), r = X.col(0) - X.col(2);
    const double aa = ea.dot(ea), bb = eb.dot(eb), ab = ea.dot(eb), ar = ea.dot(r), br = eb.dot(r);
    const double den = aa * bb - ab * ab;
    double sa = 0, sb = 0;
    if (aa > 0 && bb > 0) {
      sa = den > kDcrParallelTolerance * aa * bb ? std::clamp((ab * br - bb * ar) / den, 0.0, 1.0) : 0.0;
      sb = (ab * sa + br) / bb;
      if (sb < 0 || sb > 1) {
        sb = std::clamp(sb, 0.0, 1.0);
        sa = std::clamp((ab * sb - ar) / aa, 0.0, 1.0);
      }
    }
    c << 1 - sa, sa, -(1 - sb), -sb;
  }
  PairDistance out;
  const Vec3 gap = X * c;  // q_A - q_B
  out.distance = gap.norm();
  if (!(out.distance > 0)) return out;
  const Vec3 u = gap / out.distance;
  out.gradient = u * c.transpose();
  return out;
}

/// The gradient of a pair's constraint: s grad V (m^2) for a pair of solids (h = 0), grad dist
/// (dimensionless) for a thick one (PairThickness; s is not read).
inline PairPoints pair_gap_gradient(DcrPairKind kind, double s, double h, const PairPoints& X) {
  return h > 0.0 ? pair_distance(kind, X).gradient : PairPoints(s * pair_volume_gradient(X));
}

/// The touching tolerance on |g| over a step (m^3): kDcrTouchTolerance L |n| / 6 with L
/// from X_old and the larger |n| of X_old and X_new.
inline double dcr_touch_tolerance(DcrPairKind kind, const PairPoints& X_old, const PairPoints& X_new) {
  return kDcrTouchTolerance * pair_length_scale(kind, X_old) *
         std::max(pair_normal_norm(kind, X_old), pair_normal_norm(kind, X_new)) / 6.0;
}

/// Cosine below which two directions count as facing each other (dcr_orientation,
/// dcr_detect): a cone of about 78 degrees, wide enough for the normal cone of a cube's
/// corner (whose averaged normal makes at most 55 degrees with any direction in it).
inline constexpr double kDcrFacingTolerance = 0.2;

/// Whether the direction c (perpendicular to the edge e) lies in the outward normal cone of an
/// edge with two triangles, n1 the normal of the one in which the edge runs along e, n2 the
/// other's: the planes through the edge that support the body locally. For a convex edge,
/// (n1 x n2) . e > 0, it is the arc from n1 to n2 turning about e; a flat edge has only its
/// face's normal (left to the averaged test of dcr_orientation), a concave one none. Sign
/// tests only: no tolerance.
inline bool dcr_in_edge_cone(const Vec3& e, const Vec3& n1, const Vec3& n2, const Vec3& c) {
  return n1.cross(n2).dot(e) > 0 && n1.cross(c).dot(e) >= 0 && c.cross(n2).dot(e) >= 0;
}

/// Orientation s of the constraint g = s V (g > 0 admissible), or 0 when it cannot be told
/// (the pair is then never a penetration). N: the pair's outward normals at X_old
/// (PairNormals; 0 = none, as where the two sides of a sheet cancel).
///  - VertexFace: s = -1.
///  - EdgeEdge: the edges' outward normals n_a = N_0, n_b = N_1 against the
///    normal c = e_a x e_b of the plane through edge a parallel to edge b. Edges can touch from
///    outside only where that plane supports both bodies, c in the normal cone of one and -c
///    in that of the other: n_a . c >= kDcrFacingTolerance |n_a| |c| and
///    n_b . c <= -kDcrFacingTolerance |n_b| |c| (edge b on the +c side of edge a), or the
///    reverse. Moving edge b by d changes V by -d . c / 6, so s = -1 when b belongs on the
///    +c side, +1 on the -c side; a missing normal leaves its condition out. The averaged
///    normal stands for a cone of about 78 degrees; a sharp edge's cone (dihedral angle
///    below about 24 degrees) is wider, so when that test decides nothing and both edges have
///    their two triangles (N_2, N_3), the exact cones decide (dcr_in_edge_cone). When neither
///    holds the plane cuts through a body next to its edge: there edge b, touching edge a,
///    would already lie partly inside that body (a plane through a convex edge that does not
///    support the body meets its interior in a half-plane bounded by the edge), so the
///    bodies meet through other pairs first (an end point in a face, another edge) and this
///    pair is no constraint (s = 0; docs/contact.md "Edge pairs the normals do not orient").
///    Without any normal: the sign of V(X_old), the side the edges start on (0 when they
///    start touching, |V| <= tol).
/// With normals the orientation is a property of the bodies, not of the motion: a pair
/// that starts on the wrong side (left there by an earlier step) is not pulled through
/// again, and touching edges that move apart are not a penetration.
inline double dcr_orientation(DcrPairKind kind, const PairPoints& X_old, const PairNormals& N,
                              double tol) {
  if (kind == DcrPairKind::VertexFace) return -1.0;
  const Vec3 e_a = X_old.col(1) - X_old.col(0), e_b = X_old.col(3) - X_old.col(2);
  const Vec3 c = e_a.cross(e_b);
  const Vec3 n_a = N.col(0), n_b = N.col(1);
  const double la = n_a.norm(), lb = n_b.norm();
  if (la > 0 || lb > 0) {
    if (!(c.norm() > 0)) return 0.0;
    const double fa = n_a.dot(c), fb = n_b.dot(c), k = kDcrFacingTolerance * c.norm();
    if ((la == 0 || fa >= k * la) && (lb == 0 || fb <= -k * lb)) return -1.0;
    if ((la == 0 || fa <= -k * la) && (lb == 0 || fb >= k * lb)) return 1.0;
    const Vec3 f_a = N.col(2), f_b = N.col(3);  // the triangles in which the edges run a0 -> a1, b0 -> b1
    if (la == 0 || lb == 0 || f_a == Vec3::Zero() || f_b == Vec3::Zero()) return 0.0;
    const Vec3 g_a = n_a - f_a, g_b = n_b - f_b;  // the edges' other triangles
    if (dcr_in_edge_cone(e_a, f_a, g_a, c) && dcr_in_edge_cone(e_b, f_b, g_b, -c)) return -1.0;
    if (dcr_in_edge_cone(e_a, f_a, g_a, -c) && dcr_in_edge_cone(e_b, f_b, g_b, c)) return 1.0;
    return 0.0;
  }
  const double V0 = pair_volume(X_old);
  if (std::abs(V0) <= tol) return 0.0;
  return V0 > 0 ? 1.0 : -1.0;
}

/// A cubic c0 + c1 t + c2 t^2 + c3 t^3.
struct DcrCubic {
  double c0, c1, c2, c3;
  double operator()(double t) const { return ((c3 * t + c2) * t + c1) * t + c0; }
};

/// V(X + t D) as a cubic in t, exactly: the determinant of three columns linear in t.
inline DcrCubic pair_volume_along(const PairPoints& X, const PairPoints& D) {
  const Vec3 u0 = X.col(1) - X.col(0), v0 = X.col(2) - X.col(0), w0 = X.col(3) - X.col(0);
  const Vec3 u1 = D.col(1) - D.col(0), v1 = D.col(2) - D.col(0), w1 = D.col(3) - D.col(0);
  auto det = [](const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); };
  return {det(u0, v0, w0) / 6.0, (det(u1, v0, w0) + det(u0, v1, w0) + det(u0, v0, w1)) / 6.0,
          (det(u1, v1, w0) + det(u1, v0, w1) + det(u0, v1, w1)) / 6.0, det(u1, v1, w1) / 6.0};
}

/// Break points of [lo, hi] into pieces on which p is monotone: lo, the real roots of
/// p' inside (lo, hi) in ascending order, hi. Returns the number of points (2..4).
inline int dcr_monotone_breaks(const DcrCubic& p, double lo, double hi, std::array<double, 4>& t) {
  // p'(t) = a t^2 + b t + c; the stable quadratic formula avoids cancellation.
  const double a = 3.0 * p.c3, b = 2.0 * p.c2, c = p.c1;
  std::array<double, 2> r{};
  int nr = 0;
  if (a == 0.0) {
    if (b != 0.0) r[nr++] = -c / b;
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
      r[nr++] = q / a;
      if (q != 0.0) r[nr++] = c / q;
    }
  }
  if (nr == 2 && r[1] < r[0]) std::swap(r[0], r[1]);
  int n = 0;
  t[n++] = lo;
  for (int k = 0; k < nr; ++k)
    if (r[k] > lo && r[k] < hi) t[n++] = r[k];
  t[n++] = hi;
  return n;
}

/// Bisection on [a, b] where p(a) and p(b) lie on different sides of 0 (p(a) < 0 <= p(b)
/// or p(b) < 0 <= p(a)), down to adjacent doubles; returns the end on p(b)'s side. p: a
/// DcrCubic, or any function of one double (a thick pair's g_h).
template <class Function>
inline double dcr_bisect(const Function& p, double a, double b) {
  const bool a_negative = p(a) < 0.0;
  for (int it = 0; it < 200; ++it) {
    const double m = 0.5 * (a + b);
    if (m == a || m == b) break;
    if ((p(m) < 0.0) == a_negative) a = m;
    else b = m;
  }
  return b;
}

/// Outcome of the narrow phase on one pair over one step.
struct DcrPenetration {
  bool penetrating = false;
  double time = 0.0;         ///< t* in [0, 1]: start of the final stretch with g < 0
  double orientation = 1.0;  ///< s of g = s V (set when penetrating)
};

/// How far inside its primitives the pair's closest point lies at X: for a vertex and a
/// face the smallest barycentric coordinate of the vertex's projection on the face's plane;
/// for two edges the smallest of sa, 1 - sa, sb, 1 - sb (the line parameters of the two
/// closest points). -infinity for a degenerate triangle or parallel edges (left to the
/// neighbouring pairs). Dimensionless: >= 0 inside, 0 on the boundary.
inline double dcr_inside_margin(DcrPairKind kind, const PairPoints& X) {
  constexpr double kOutside = -std::numeric_limits<double>::infinity();
  if (kind == DcrPairKind::VertexFace) {
    const Vec3 e1 = X.col(2) - X.col(1), e2 = X.col(3) - X.col(1), w = X.col(0) - X.col(1);
    const Vec3 nrm = e1.cross(e2);
    const double nn = nrm.squaredNorm();
    if (!(nn > kDcrParallelTolerance * e1.squaredNorm() * e2.squaredNorm())) return kOutside;
    const double lb = w.cross(e2).dot(nrm) / nn, lc = e1.cross(w).dot(nrm) / nn;
    return std::min({1.0 - lb - lc, lb, lc});
  }
  const Vec3 ea = X.col(1) - X.col(0), eb = X.col(3) - X.col(2), w = X.col(0) - X.col(2);
  const double aa = ea.dot(ea), ab = ea.dot(eb), bb = eb.dot(eb), aw = ea.dot(w), bw = eb.dot(w);
  const double den = aa * bb - ab * ab;
  if (!(den > kDcrParallelTolerance * aa * bb)) return kOutside;
  const double sa = (ab * bw - bb * aw) / den, sb = (aa * bw - ab * aw) / den;
  return std::min({sa, 1.0 - sa, sb, 1.0 - sb});
}

/// Whether the pair penetrated during the step, positions moving linearly from X_old
/// (t = 0) to X_new (t = 1); N: the pair's outward normals at X_old (dcr_orientation).
/// Penetration: g(X_new) < -tol, and at the time t* where the final stretch of negative g
/// begins (g(t*) = 0, found on the monotone pieces of the cubic g(t), or t* = 0 when the
/// pair starts touching, |g| <= tol) the vertex lies in the triangle / the two segments
/// cross: dcr_inside_margin >= -kDcrInsideTolerance (so that a vertex crossing exactly on
/// an edge shared by two triangles is caught by both).
/// A crossing on the boundary (margin within kDcrInsideTolerance of 0), and a pair that
/// starts touching, which has no crossing point of its own (its inside test is made where
/// the motion takes it, at X_new), may be a graze rather than a contact, and count only
///  - for a vertex, when it faces the triangle: its outward normal against the triangle's,
///    cosine <= -kDcrFacingTolerance (a vertex of one body's face, sliding in the plane of
///    another body's bottom face, meets that body's side face exactly on its edge);
///  - for two edges, when they still cross at X_new (an edge's end point sliding over
///    another edge in the plane of its face crosses it only at that instant).
/// Inside a triangle too, a vertex crossing counts only when its outward normal does not
/// lean to the face's outer side (n_vertex . n_face <= 0; a zero normal, a sheet's, passes).
/// Robust for fast motion (exact cubic in t, no sampling), grazing (g touches 0 and
/// returns: g(X_new) > -tol), touching at the end (|g| <= tol), touching at the start
/// (coincident faces) and degenerate geometry.
/// tol = dcr_touch_tolerance(kind, X_old, X_new).
/// normals: a callable returning the pair's PairNormals, called only for the few candidates
/// that pass the cheap tests (at most once), so that a caller can compute them on demand.
template <std::invocable Normals>
inline DcrPenetration dcr_detect_thick(DcrPairKind kind, const PairPoints& X_old, const PairPoints& X_new,
                                       Normals&&, const PairThickness& th);

template <std::invocable Normals>
inline DcrPenetration dcr_detect(DcrPairKind kind, const PairPoints& X_old, const PairPoints& X_new,
                                 Normals&& normals, const PairThickness& th = {}) {
  if (th.reach > 0.0) return dcr_detect_thick(kind, X_old, X_new, normals, th);
  DcrPenetration out;
  // Exact exits before the normals, in this order of cost. A vertex and a face (s = -1):
  // s V(X_new) < -tol needs V(X_new) > 0. Two edges whose volume has the same sign at both
  // ends and is not touching at the start: whatever s is, a penetration needs V to vanish
  // inside the step (else g < -tol all along, or g > 0 at the end), which the cubic's
  // coefficients exclude when |c0| > |c1| + |c2| + |c3|.
  const double V_new = pair_volume(X_new);
  if (kind == DcrPairKind::VertexFace && !(V_new > 0.0)) return out;
  const double tol = dcr_touch_tolerance(kind, X_old, X_new);
  const DcrCubic V = pair_volume_along(X_old, X_new - X_old);
  if (kind == DcrPairKind::EdgeEdge && V.c0 * V_new > 0.0 && std::abs(V.c0) > tol &&
      std::abs(V.c0) > std::abs(V.c1) + std::abs(V.c2) + std::abs(V.c3))
    return out;
  // Filled on first use; zero before that so that N is never read undefined (the flag
  // alone left GCC unable to prove it, -Wmaybe-uninitialized).
  PairNormals N = PairNormals::Zero();
  bool have_normals = false;
  auto pair_normals = [&]() -> const PairNormals& {
    if (!have_normals) N = normals();
    have_normals = true;
    return N;
  };
  out.orientation = kind == DcrPairKind::VertexFace ? -1.0 : dcr_orientation(kind, X_old, pair_normals(), tol);
  const double s = out.orientation;
  if (!(s * V_new < -tol)) return out;  // also s = 0

  const DcrCubic g{s * V.c0, s * V.c1, s * V.c2, s * V.c3};
  const bool touching = std::abs(g.c0) <= tol;
  std::array<double, 4> br;
  const int n = dcr_monotone_breaks(g, 0.0, 1.0, br);
  double t_star = -1.0;
  for (int k = n - 2; k >= 0; --k) {
    const double ga = g(br[k]);
    if (ga >= 0.0) {
      t_star = g(br[k + 1]) < 0.0 ? dcr_bisect(g, br[k + 1], br[k]) : br[k + 1];
      break;
    }
    if (k == 0 && ga >= -tol) t_star = 0.0;
  }
  if (t_star < 0.0) return out;  // behind the face / the other edge all step long

  const double margin =
      dcr_inside_margin(kind, touching ? X_new : PairPoints(X_old + t_star * (X_new - X_old)));
  if (!(margin >= -kDcrInsideTolerance)) return out;
  const bool on_boundary = touching || margin <= kDcrInsideTolerance;
  if (kind == DcrPairKind::VertexFace) {
    // A vertex arriving from outside has its body on the face's outer side, so its outward
    // normal does not lean to that side (unless its normal cone is wider than 90 degrees: a
    // blade's tip, left to its edges' pairs). One that leans came in from the side: a copy
    // of a crack-front node lying in the coplanar face of the piece across the crack, whose
    // pair and its mirror image pushed each other to the sweep cap (docs/contact.md
    // "Crack-front copies"). On the boundary the vertex must face the triangle (issue 7).
    const Vec3 n_face = (X_old.col(2) - X_old.col(1)).cross(X_old.col(3) - X_old.col(1));
    const Vec3 n_vertex = pair_normals().col(0);
    const double facing = on_boundary ? -kDcrFacingTolerance * n_vertex.norm() * n_face.norm() : 0.0;
    if (n_vertex.dot(n_face) > facing) return out;
  } else if (on_boundary && !(dcr_inside_margin(kind, X_new) >= -kDcrInsideTolerance)) {
    return out;
  }
  out.penetrating = true;
  out.time = t_star;
  return out;
}

/// Samples of g_h(t) over a step in dcr_detect_thick (its final sign change is bracketed on
/// them, then bisected).
inline constexpr int kDcrThickSamples = 16;

/// dcr_detect for a thick pair (th.reach = h > 0, PairThickness): g_h(t) = dist - h at
/// X_old + t (X_new - X_old), piecewise smooth in t (no polynomial). Penetration:
/// g_h(1) < -tol (tol = kDcrTouchTolerance L, L the longest edge), with t* the start of the
/// final stretch of g_h < 0 (bracketed on kDcrThickSamples samples, bisected), or t* = 0 when
/// g_h < 0 all step long (a pair starting inside the layer: a vertex sliding along the
/// sheet into a neighbour's reach, or one left by an earlier step). No inside test: the
/// distance is to the whole primitive (corners and edges included), and no orientation
/// (out.orientation = 1, not read). The normals are not read.
template <std::invocable Normals>
inline DcrPenetration dcr_detect_thick(DcrPairKind kind, const PairPoints& X_old, const PairPoints& X_new,
                                       Normals&&, const PairThickness& th) {
  DcrPenetration out;
  const double h = th.reach, tol = kDcrTouchTolerance * pair_length_scale(kind, X_old);
  const PairPoints D = X_new - X_old;
  auto g = [&](double t) { return pair_distance(kind, PairPoints(X_old + t * D)).distance - h; };
  if (!(g(1.0) < -tol)) return out;
  double t_star = 0.0, after = 1.0;
  for (int k = kDcrThickSamples - 1; k >= 0; --k) {
    const double t = static_cast<double>(k) / kDcrThickSamples;
    if (g(t) >= 0.0) {
      t_star = dcr_bisect(g, after, t);  // g(t) >= 0 > g(after): the end where g >= 0
      break;
    }
    after = t;
  }
  out.penetrating = true;
  out.time = t_star;
  return out;
}

/// dcr_detect with the pair's normals at hand.
inline DcrPenetration dcr_detect(DcrPairKind kind, const PairPoints& X_old, const PairPoints& X_new,
                                 const PairNormals& N, const PairThickness& th = {}) {
  return dcr_detect(kind, X_old, X_new, [&] { return N; }, th);
}

/// Removes the penetration of a pair in place by the mass-weighted projection
///   x_i <- x_i + mu W_i grad_i g(X_contact),  mu > 0,
/// with g(mu) = g_target = gap L |n| / 6 (a separation of gap L, L and |n| from
/// pair_length_scale and pair_normal_norm at X): the smallest positive root of this
/// cubic in mu. X_contact is the configuration at the contact time t* (g = 0): there the
/// gradient is the contact normal weighted by the closest-point coordinates (vertex and
/// barycentric point of the face / the crossing points of the edges), the closest-point
/// projection of [CW]; the gradient at the penetrated X would also carry terms of the
/// order of depth x edge length that tilt nearly parallel edges instead of separating
/// them. The direction is M^-1 grad g, so sum_i m_i dx_i = 0 (the pair's centre of mass
/// does not move) and nodes with W_i = 0 stay put. When the cubic has no root in reach,
/// the step goes to its maximum and the gradient is re-evaluated at X (at most 4 passes).
/// Returns whether g(X) > 0 afterwards (false e.g. when all four nodes are fixed).
/// `shift` (if any) accumulates the mass-weighted displacements mu grad g (kg m), the
/// projection's "impulse" on each node (a rigid body moves by it: PairMobility).
template <class Weights>
bool dcr_project_thick(DcrPairKind kind, double reach, const PairPoints& X_contact, PairPoints& X,
                       const Weights& inv_mass, double gap, PairPoints* shift);

template <class Weights>
bool dcr_project(DcrPairKind kind, double orientation, const PairPoints& X_contact, PairPoints& X,
                 const Weights& inv_mass, double gap, PairPoints* shift = nullptr, double reach = 0.0) {
  if (reach > 0.0) return dcr_project_thick(kind, reach, X_contact, X, inv_mass, gap, shift);
  const double s = orientation;
  const double target = gap * pair_length_scale(kind, X) * pair_normal_norm(kind, X) / 6.0;
  for (int pass = 0; pass < 4; ++pass) {
    const PairPoints G = s * pair_volume_gradient(pass == 0 ? X_contact : X);
    const PairPoints D = weighted(G, inv_mass);
    DcrCubic g = pair_volume_along(X, D);
    g = {s * g.c0 - target, s * g.c1, s * g.c2, s * g.c3};
    if (g.c0 >= 0.0) return true;
    if (!(g.c1 > 0.0)) continue;  // not a separating direction at X (or all nodes fixed)
    const double hi = 16.0 * (-g.c0 / g.c1);
    std::array<double, 4> br;
    const int n = dcr_monotone_breaks(g, 0.0, hi, br);
    double mu = 0.0;
    for (int k = 0; k + 1 < n; ++k) {
      if (g(br[k + 1]) >= 0.0) {
        mu = dcr_bisect(g, br[k], br[k + 1]);
        break;
      }
      if (g(br[k + 1]) > g(mu)) mu = br[k + 1];
    }
    X += mu * D;
    if (shift) *shift += mu * G;
    if (g(mu) >= 0.0) break;
  }
  return s * pair_volume(X) > 0.0;
}

/// dcr_project for a thick pair (reach = h > 0): the same mass-weighted move
/// x_i += mu W_i grad_i g_h (at X_contact in the first pass, at X after) to g_h = gap L (m),
/// mu the smallest root found by doubling from the linear estimate -g_h(0) / (G . W G) (up
/// to 32 times it) and bisection, since g_h(mu) is no cubic.
template <class Weights>
bool dcr_project_thick(DcrPairKind kind, double reach, const PairPoints& X_contact, PairPoints& X,
                       const Weights& inv_mass, double gap, PairPoints* shift) {
  const double h = reach;
  const double target = gap * pair_length_scale(kind, X);  // m, as g_h
  auto g_h = [&](const PairPoints& Y) { return pair_distance(kind, Y).distance - h; };
  for (int pass = 0; pass < 4; ++pass) {
    const PairPoints G = pair_distance(kind, pass == 0 ? X_contact : X).gradient;
    const PairPoints D = weighted(G, inv_mass);
    auto g = [&](double mu) { return g_h(PairPoints(X + mu * D)) - target; };
    const double g0 = g(0.0), slope = (G.array() * D.array()).sum();
    if (g0 >= 0.0) return true;
    if (!(slope > 0.0)) continue;  // all nodes fixed, or no separating direction
    double lo = 0.0, hi = -g0 / slope;
    for (int k = 0; k < 5 && g(hi) < 0.0; ++k) lo = hi, hi *= 2.0;  // up to 32x
    // The root bracketed by [lo, hi], or the most reached (the gradient is then re-evaluated at X).
    const double mu = g(hi) >= 0.0 ? dcr_bisect(g, lo, hi) : hi;
    X += mu * D;
    if (shift) *shift += mu * G;
    if (g(0.0) >= 0.0) break;
  }
  return g_h(X) > 0.0;
}

/// The node's mass for the angular-momentum counterpart of a projection (1/kg -> kg), or 0
/// for a node that is not free: a fixed node, one with a held component, a node of a rigid
/// body (moved by its body, PairMobility).
template <class Derived>
double dcr_free_mass(const Eigen::MatrixBase<Derived>& w, int i) {
  if constexpr (Derived::RowsAtCompileTime == 3) {
    return w.col(i).minCoeff() > 0 ? 1.0 / w.col(i).maxCoeff() : 0.0;
  } else {
    return w[i] > 0 ? 1.0 / w[i] : 0.0;
  }
}
inline double dcr_free_mass(const PairMobility& m, int i) {
  return m.rigid[i] || !(m.w.col(i).minCoeff() > 0) ? 0.0 : 1.0 / m.w.col(i).maxCoeff();
}

/// The velocity counterpart of a projection that keeps sum m x x v (docs/contact.md
/// "Angular momentum: the projection's counterpart"). A move of the positions from X_before
/// to X at fixed velocities V changes the pair's angular momentum about the origin by
///   dL = sum_i m_i (x_i - x_before_i) x v_i
/// (its linear momentum not at all: dcr_project keeps the centre of mass). The velocity
/// change of least kinetic energy that gives back -dL and no linear momentum is a rigid spin
/// of the pair's nodes about their centre of mass c at X:
///   dv_i = Omega x (x_i - c),   I Omega = -dL,   I = sum_i m_i (|r_i|^2 1 - r_i r_i^T),
/// since sum m_i dv_i = Omega x sum m_i r_i = 0 and sum m_i x_i x dv_i = I Omega (I the
/// nodes' inertia about c). Only for pairs of four free nodes (dcr_free_mass > 0): a pair
/// with a support or a rigid body's node is left as it was (the support takes up momenta
/// anyway; the body is moved from its own state, RigidBodies::apply_contact). V is updated
/// in place; returns the kinetic energy the counterpart took out, J (signed: the work of the
/// torque on the pair's own spin, first order in |dx| / |r|), and adds the impulses m_i dv_i
/// (summing to 0) to `applied`. Nothing is done
/// when dL = 0 or I is nearly singular, det I <= 1e-12 (tr I)^3 (four points nearly on one
/// line; a triangle or two edges that detection resolves are far from it).
template <class Weights>
double dcr_keep_angular_momentum(const PairPoints& X_before, const PairPoints& X, PairPoints& V,
                                 const Weights& inv_mass, PairPoints* applied = nullptr) {
  PairWeights m;
  Vec3 dL = Vec3::Zero(), c = Vec3::Zero();
  double M = 0;
  for (int i = 0; i < 4; ++i) {
    m[i] = dcr_free_mass(inv_mass, i);
    if (m[i] == 0) return 0.0;
    dL += m[i] * (X.col(i) - X_before.col(i)).cross(V.col(i));
    c += m[i] * X.col(i);
    M += m[i];
  }
  if (dL == Vec3::Zero()) return 0.0;
  c /= M;
  Mat3 I = Mat3::Zero();
  for (int i = 0; i < 4; ++i) {
    const Vec3 r = X.col(i) - c;
    I += m[i] * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  }
  const Eigen::LLT<Mat3> llt(I);
  if (llt.info() != Eigen::Success || !(I.determinant() > 1e-12 * std::pow(I.trace(), 3))) return 0.0;
  const Vec3 omega = -llt.solve(dL);
  double taken = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec3 dv = omega.cross(X.col(i) - c);
    taken -= m[i] * (V.col(i).dot(dv) + 0.5 * dv.squaredNorm());
    V.col(i) += dv;
    if (applied) applied->col(i) += m[i] * dv;
  }
  return taken;
}

/// The momentum transfer of one resolved pair.
struct DcrImpulse {
  double normal = 0.0;      ///< |normal impulse| on the vertex / on edge a, N s
  double friction = 0.0;    ///< |slide impulse| on the vertex / on edge a, N s
  double dissipated = 0.0;  ///< kinetic energy lost, J (>= 0; 0 for e = 1, mu = 0)
  bool stick = false;       ///< friction stopped the sliding
  PairPoints applied = PairPoints::Zero();  ///< the impulse on each node (columns), N s; they sum to 0
};

/// Velocity update of a pair in contact at X by momentum decompositions ([CW] sec. 3-4,
/// "Solving the collision equations"), V (columns, m/s) updated in place.
/// Normal: with G = grad g(X) (pair_gap_gradient: grad dist for a thick pair, reach = h), W = M^-1 (inv_mass, 0 = fixed node or held component: weighted),
///   v_n = G . V / (G . W G)  [kg m/s];  if v_n < 0 (approaching):
///   V' = V - (1 + e) v_n W G,  dissipated = (1 - e^2) v_n^2 (G . W G) / 2.
/// Friction: the contact point splits as sum_i c_i x_i (vertex minus the barycentric point
/// of the face; or the closest points of the two edges), with sum c_i = 0 and sum over the
/// vertex / edge a of c_i = 1. Its tangential relative velocity gives the slide direction
/// t = sum_i d_i x_i (d_i from the two edge vectors spanning the tangent plane, sum d_i = 0);
/// the slide generator F is the gradient of the translation- and rotation-invariant
/// phi = (sum c_i x_i) . (sum d_i x_i), made W-orthogonal to G (so the normal part is left
/// alone): zero net force and zero net torque, exactly. Slide decomposition
///   v_s = F . V / (F . W F);  needed impulse v_s, limit mu J_n / |sum_A F_i|
/// (J_n = normal impulse on side A = the vertex / edge a); stick when within the limit,
/// else slide with the limit: V' = V - j W F, dissipated j (F . W F) (v_s - j / 2).
template <class Weights>
DcrImpulse dcr_impulse(DcrPairKind kind, double orientation, const PairPoints& X, PairPoints& V,
                       const Weights& inv_mass, const DcrLaw& law, double reach = 0.0) {
  DcrImpulse out;
  const PairPoints G = pair_gap_gradient(kind, orientation, reach, X);
  const PairPoints D = weighted(G, inv_mass);
  const double q = (G.array() * D.array()).sum();
  if (!(q > 0.0)) return out;
  const double v_n = (G.array() * V.array()).sum() / q;
  if (!(v_n < 0.0)) return out;  // already separating
  const double e = law.restitution;
  V -= ((1.0 + e) * v_n) * D;
  out.applied = (-(1.0 + e) * v_n) * G;
  out.dissipated = 0.5 * (1.0 - e * e) * v_n * v_n * q;
  const int side_a = kind == DcrPairKind::VertexFace ? 1 : 2;  // nodes 0..side_a-1
  const Vec3 G_a = G.leftCols(side_a).rowwise().sum();
  out.normal = -(1.0 + e) * v_n * G_a.norm();
  if (!(law.friction > 0.0)) return out;

  // Contact point coefficients c, tangent basis e1 = sum d1_i x_i, e2 = sum d2_i x_i, normal.
  PairWeights c, d1, d2;
  Vec3 nrm;
  if (kind == DcrPairKind::VertexFace) {
    const Vec3 e1 = X.col(2) - X.col(1), e2 = X.col(3) - X.col(1), w = X.col(0) - X.col(1);
    nrm = e1.cross(e2);
    const double nn = nrm.squaredNorm();
    if (!(nn > 0.0)) return out;
    const double lb = w.cross(e2).dot(nrm) / nn, lc = e1.cross(w).dot(nrm) / nn;
    c << 1.0, -(1.0 - lb - lc), -lb, -lc;
    d1 << 0.0, -1.0, 1.0, 0.0;
    d2 << 0.0, -1.0, 0.0, 1.0;
  } else {
    const Vec3 ea = X.col(1) - X.col(0), eb = X.col(3) - X.col(2), w = X.col(0) - X.col(2);
    nrm = ea.cross(eb);
    const double aa = ea.dot(ea), ab = ea.dot(eb), bb = eb.dot(eb), aw = ea.dot(w), bw = eb.dot(w);
    const double den = aa * bb - ab * ab;
    if (!(den > 0.0)) return out;
    const double sa = std::clamp((ab * bw - bb * aw) / den, 0.0, 1.0);
    const double sb = std::clamp((aa * bw - ab * aw) / den, 0.0, 1.0);
    c << 1.0 - sa, sa, -(1.0 - sb), -sb;
    d1 << -1.0, 1.0, 0.0, 0.0;
    d2 << 0.0, 0.0, -1.0, 1.0;
  }
  const Vec3 n_hat = nrm.normalized();
  const Vec3 v_rel = V * c;
  const Vec3 v_t = v_rel - v_rel.dot(n_hat) * n_hat;
  const double v_scale = V.colwise().norm().maxCoeff();
  if (!(v_t.norm() > 1e-14 * v_scale)) return out;  // no sliding
  const Vec3 t_hat = v_t.normalized();
  const Vec3 e1 = X * d1, e2 = X * d2;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  const double alpha = (g22 * e1.dot(t_hat) - g12 * e2.dot(t_hat)) / det;
  const double beta = (g11 * e2.dot(t_hat) - g12 * e1.dot(t_hat)) / det;
  const PairWeights d = alpha * d1 + beta * d2;
  const Vec3 r = X * c, t = X * d;
  PairPoints F = t * c.transpose() + r * d.transpose();  // grad of phi = r . t
  F -= ((F.array() * D.array()).sum() / q) * G;
  const PairPoints DF = weighted(F, inv_mass);
  const double qf = (F.array() * DF.array()).sum();
  if (!(qf > 0.0)) return out;
  const double v_s = (F.array() * V.array()).sum() / qf;
  if (!(v_s > 0.0)) return out;
  const double F_a = F.leftCols(side_a).rowwise().sum().norm();
  const double j_max = law.friction * out.normal / F_a;
  out.stick = v_s <= j_max;
  const double j = out.stick ? v_s : j_max;
  V -= j * DF;
  out.applied -= j * F;
  out.friction = j * F_a;
  out.dissipated += j * qf * (v_s - 0.5 * j);
  return out;
}

/// Outcome of dcr_resolve_pair.
struct DcrPairResponse {
  bool active = false;  ///< the pair penetrated and was resolved
  bool separated = false;  ///< the projection reached g > 0
  DcrImpulse impulse;
  /// The mass-weighted position change of each node, kg m: the projections' mu grad g and
  /// the free flight's tau times the impulse (Middle, Impact); they sum to 0.
  PairPoints shift = PairPoints::Zero();
  /// The kinetic energy the projections' velocity counterpart took out
  /// (dcr_keep_angular_momentum), J, signed: contact work that is not the law's dissipation.
  double work = 0.0;
};

/// One DCR resolution of a pair over a step of the central-difference predictor
/// X_new = X_old + dt V (V the mid-step velocity, half_dt = dt / 2): detect (dcr_detect on
/// X_old -> X_new, N the pair's outward normals); if the pair penetrates, resolve it with the
/// collision placed (law.placement)
///  - End: at the end of the step ([CW]'s impact time approximation): project X_new
///    (dcr_project, direction from the configuration at t*), then the impulse at the projected
///    positions (dcr_impulse);
///  - Middle / Impact: at a time tau before the end of the step, tau = half_dt (Middle) or
///    (1 - t*) dt (Impact, the contact time): a free flight back to X_c = X_new - tau V, the
///    impulse there, a free flight on: V' = V + dV (dcr_impulse at X_c), X_new += tau dV;
///    then dcr_project only if the pair is still closer than the gap.
/// A velocity change dv at the mid step that moves x(n+1) by dx changes the central-difference
/// total energy by about f(n+1) . (half_dt dv - dx) besides the impulse's own kinetic-energy
/// balance: End has dx ~ (1 - t*) half_dt dv and loses t* half_dt f . dv per impact, Middle
/// has dx = half_dt dv (no first-order term), Impact dx = (1 - t*) dt dv (a term
/// (t* - 1/2) dt f . dv, of either sign). An impulse that is a gradient of rotation-invariant
/// functions at X_c between two free flights keeps sum m v and sum x x m v exactly, whatever
/// tau. X_c = X_new - tau V is kept by the update, so repeated resolutions of the pair in a
/// step with the same tau act at the same configuration. The final projection (at fixed
/// velocities) is the exception that moves angular momentum and energy: it is needed when the
/// impulse alone does not separate the pair (e < 1, pairs coupled through shared nodes,
/// strongly curved g(t)). X_new and V are updated in place. th: the pair's thickness
/// (PairThickness; a pair of solids by default): a thick pair, g = g_h, is placed at the end
/// of the step whatever law.placement says.
template <class Weights>
DcrPairResponse dcr_resolve_pair(DcrPairKind kind, const PairPoints& X_old, PairPoints& X_new, PairPoints& V,
                                 const PairNormals& N, const Weights& inv_mass, const DcrLaw& law,
                                 double half_dt, const PairThickness& th = {}) {
  DcrPairResponse out;
  const DcrPenetration pen = dcr_detect(kind, X_old, X_new, N, th);
  if (!pen.penetrating) return out;
  out.active = true;
  const double s = pen.orientation, h = th.reach;
  const PairPoints X_contact = X_old + pen.time * (X_new - X_old);
  if (law.placement == DcrPlacement::End || h > 0.0) {
    const PairPoints X_before = X_new;
    out.separated = dcr_project(kind, s, X_contact, X_new, inv_mass, law.gap, &out.shift, h);
    PairPoints spin = PairPoints::Zero();
    out.work = dcr_keep_angular_momentum(X_before, X_new, V, inv_mass, &spin);
    out.impulse = dcr_impulse(kind, s, X_new, V, inv_mass, law, h);
    out.impulse.applied += spin;
    return out;
  }
  const double tau =
      law.placement == DcrPlacement::Middle ? half_dt : 2.0 * half_dt * (1.0 - pen.time);
  const PairPoints X_c = X_new - tau * V;
  const PairPoints V_before = V;
  out.impulse = dcr_impulse(kind, s, X_c, V, inv_mass, law);
  X_new += tau * (V - V_before);
  out.shift = tau * out.impulse.applied;
  // What is left is projected, to no less than twice the touching tolerance and, in the
  // middle, to no more than half the separation the pair had at the start of the step (an
  // elastic impulse at X_mid brings a pair back to it, so the projection takes up only what
  // the impulse could not). At the contact time an elastic impulse leaves the pair apart by
  // (1 - t*) / t* of that: only the touching tolerance is asked for.
  const double unit = pair_length_scale(kind, X_new) * pair_normal_norm(kind, X_new) / 6.0;
  const double touch = 2.0 * dcr_touch_tolerance(kind, X_old, X_new);
  const double target =
      law.placement == DcrPlacement::Middle
          ? std::max(touch, std::min(law.gap * unit, 0.5 * s * pair_volume(X_old)))
          : touch;
  if (s * pair_volume(X_new) >= target) {
    out.separated = true;
    return out;
  }
  const PairPoints X_before = X_new;
  out.separated = dcr_project(kind, s, X_contact, X_new, inv_mass, target / unit, &out.shift);
  out.work = dcr_keep_angular_momentum(X_before, X_new, V, inv_mass, &out.impulse.applied);
  return out;
}

}  // namespace shatter
