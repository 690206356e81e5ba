// DCR sweeps (contact/dcr.hpp) on small stacks of sheets: every penetration is
// removed (checked by an independent height-field test, not by the DCR kernels),
// fixed nodes stay, momentum and energy are accounted for, and the result is
// bitwise identical for 1, 2 and 4 threads and to a one-by-one Gauss-Seidel pass over
// the pairs found, in key order (contact/dcr_order.hpp), round after round.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <random>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "kernels/error.hpp"
#include "expect_close.hpp"

using namespace shatter;

namespace {

struct Sheet {
  std::vector<std::array<Index, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<std::array<Index, 2>> edges;      // e0 < e1
  std::vector<Index> vertices;
};

// Stacked bodies, each a bottom sheet (outside = -z) and a top sheet (outside = +z); body 0
// has only a top sheet. Gaps of 0.2 between bodies at the start; body k moves down by
// 0.3 k over the step, so neighbouring bodies overlap by about 0.1 at its end.
struct Stack {
  std::vector<Vec3> x_old, x_new, v;
  std::vector<double> inv_mass;
  std::vector<std::pair<Sheet, Sheet>> contacts;  // (lower top sheet, upper bottom sheet)
  ContactPairs pairs;
  std::vector<SurfaceTriangle>
      triangles;  // every sheet's, for the outward normals (none: no normals)
};

Sheet make_sheet(Stack& s, int n, Vec3 origin, bool outside_up, const Vec3& velocity, double inv_mass_scale,
                 std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1), m(1, 2);
  Sheet sheet;
  const Index first = static_cast<Index>(s.x_old.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec3 x = origin + Vec3(i + 0.05 * u(rng), j + 0.05 * u(rng), 0.02 * u(rng));
      const Vec3 vel = velocity + 0.05 * Vec3(u(rng), u(rng), u(rng));
      sheet.vertices.push_back(static_cast<Index>(s.x_old.size()));
      s.x_old.push_back(x);
      s.x_new.push_back(x + vel);  // dt = 1 s
      s.v.push_back(vel);
      s.inv_mass.push_back(inv_mass_scale / m(rng));
    }
  auto id = [&](int i, int j) { return first + j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::array<Index, 3> t0{id(i, j), id(i + 1, j), id(i + 1, j + 1)}, t1{id(i, j), id(i + 1, j + 1), id(i, j + 1)};
      if (!outside_up) std::swap(t0[1], t0[2]), std::swap(t1[1], t1[2]);
      sheet.triangles.push_back(t0);
      sheet.triangles.push_back(t1);
      s.triangles.push_back({t0, 0});
      s.triangles.push_back({t1, 0});
    }
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      if (i < n) sheet.edges.push_back({id(i, j), id(i + 1, j)});
      if (j < n) sheet.edges.push_back({id(i, j), id(i, j + 1)});
      if (i < n && j < n) sheet.edges.push_back({id(i, j), id(i + 1, j + 1)});
    }
  return sheet;
}

struct XyBox {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  void add(const Vec3& x) {
    lo = lo.cwiseMin(x.head<2>());
    hi = hi.cwiseMax(x.head<2>());
  }
  bool overlaps(const XyBox& o, double pad) const {
    return (lo.array() - pad <= o.hi.array()).all() && (o.lo.array() - pad <= hi.array()).all();
  }
};

template <class Nodes>
XyBox swept_box(const Stack& s, const Nodes& nodes) {
  XyBox b;
  for (const Index n : nodes) b.add(s.x_old[n]), b.add(s.x_new[n]);
  return b;
}

// Candidate pairs between the facing sheets of neighbouring bodies: every vertex-face and
// edge-edge pair whose swept xy boxes overlap (a brute-force broad phase), canonical order.
void add_candidates(Stack& s, const Sheet& lower, const Sheet& upper) {
  const double pad = 0.5;  // room for the projections of a collapsing stack
  auto vf = [&](const Sheet& verts, const Sheet& faces) {
    for (const Index p : verts.vertices)
      for (const auto& t : faces.triangles)
        if (swept_box(s, std::array{p}).overlaps(swept_box(s, t), pad))
          s.pairs.push_back({ContactPair::VertexFace, {p, t[0], t[1], t[2]}});
  };
  vf(upper, lower);
  vf(lower, upper);
  for (const auto& e : lower.edges)
    for (const auto& f : upper.edges)
      if (swept_box(s, e).overlaps(swept_box(s, f), pad)) {
        const bool e_first = e < f;
        const auto& a = e_first ? e : f;
        const auto& b = e_first ? f : e;
        s.pairs.push_back({ContactPair::EdgeEdge, {a[0], a[1], b[0], b[1]}});
      }
}

Sheet flipped(Sheet sheet) {
  for (auto& t : sheet.triangles) std::swap(t[1], t[2]);
  return sheet;
}

// thick: body k = separate bottom and top sheets (each vertex in contact with one
// neighbour); thin: body k = one two-sided sheet at z = 0.2 k moving down by 0.25 k,
// touching both neighbours, so resolving one contact can push a vertex into the next:
// the stack collapses into a pile on the ground and Gauss-Seidel needs many sweeps.
Stack make_stack(int bodies, int n, bool fixed_ground, std::uint64_t seed, bool thin = false) {
  std::mt19937_64 rng(seed);
  Stack s;
  Sheet below = make_sheet(s, n, Vec3(0, 0, 0.8 * !thin), true, Vec3::Zero(), fixed_ground ? 0.0 : 1.0, rng);
  for (int k = 1; k < bodies; ++k) {
    const Vec3 velocity(0.03 * k, -0.02 * k, (thin ? -0.25 : -0.3) * k);
    const Vec3 shift(0.37 * k - std::floor(0.37 * k), 0.23 * k - std::floor(0.23 * k), 0);
    if (thin) {
      const Sheet sheet = make_sheet(s, n, Vec3(0, 0, 0.2 * k) + shift, true, velocity, 1.0, rng);
      for (const auto& t : flipped(sheet).triangles)
        s.triangles.push_back({t, 0});  // its underside
      add_candidates(s, below, flipped(sheet));
      s.contacts.emplace_back(below, sheet);
      below = sheet;
      continue;
    }
    const Sheet bottom = make_sheet(s, n, Vec3(0, 0, k) + shift, false, velocity, 1.0, rng);
    const Sheet top = make_sheet(s, n, Vec3(0.5, 0.5, k + 0.8) - shift, true, velocity, 1.0, rng);
    add_candidates(s, below, bottom);
    s.contacts.emplace_back(below, bottom);
    below = top;
  }
  std::sort(s.pairs.begin(), s.pairs.end());
  s.pairs.erase(std::unique(s.pairs.begin(), s.pairs.end()), s.pairs.end());
  return s;
}

std::string sci(double x) {
  std::ostringstream os;
  os << std::scientific << std::setprecision(2) << x;
  return os.str();
}

// --- the independent checker: sheets are height fields over xy -------------------------

// Height of triangle t at xy point q, if q projects inside it.
std::optional<double> height_in(const std::vector<Vec3>& x, const std::array<Index, 3>& t, const Eigen::Vector2d& q) {
  const Eigen::Vector2d a = x[t[0]].head<2>(), b = x[t[1]].head<2>(), c = x[t[2]].head<2>();
  const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  const double l1 = ((q - a).x() * (c - a).y() - (q - a).y() * (c - a).x()) / det;
  const double l2 = ((b - a).x() * (q - a).y() - (b - a).y() * (q - a).x()) / det;
  const double l0 = 1 - l1 - l2;
  if (l0 < 0 || l1 < 0 || l2 < 0) return std::nullopt;
  return l0 * x[t[0]].z() + l1 * x[t[1]].z() + l2 * x[t[2]].z();
}

// Number of places where the upper sheet dips below the lower one: vertices of either
// sheet against the other sheet's faces, and crossings of edges seen from above.
int count_penetrations(const std::vector<Vec3>& x, const Sheet& lower, const Sheet& upper) {
  const double tol = 1e-10;  // DCR treats distances below 1e-11 x edge length as touching
  int bad = 0;
  for (const Index p : upper.vertices)
    for (const auto& t : lower.triangles)
      if (const auto h = height_in(x, t, x[p].head<2>()); h && x[p].z() < *h - tol) ++bad;
  for (const Index p : lower.vertices)
    for (const auto& t : upper.triangles)
      if (const auto h = height_in(x, t, x[p].head<2>()); h && x[p].z() > *h + tol) ++bad;
  for (const auto& e : lower.edges)
    for (const auto& f : upper.edges) {
      const Eigen::Vector2d p = x[e[0]].head<2>(), r = x[e[1]].head<2>() - p;
      const Eigen::Vector2d q = x[f[0]].head<2>(), d = x[f[1]].head<2>() - q;
      const double den = r.x() * d.y() - r.y() * d.x();
      if (std::abs(den) < 1e-12) continue;
      const double s = ((q - p).x() * d.y() - (q - p).y() * d.x()) / den;
      const double u = ((q - p).x() * r.y() - (q - p).y() * r.x()) / den;
      if (s < 0 || s > 1 || u < 0 || u > 1) continue;
      const double z_lower = (1 - s) * x[e[0]].z() + s * x[e[1]].z();
      const double z_upper = (1 - u) * x[f[0]].z() + u * x[f[1]].z();
      if (z_upper < z_lower - tol) ++bad;
    }
  return bad;
}

int count_penetrations(const Stack& s, const std::vector<Vec3>& x) {
  int bad = 0;
  for (const auto& [lower, upper] : s.contacts) bad += count_penetrations(x, lower, upper);
  return bad;
}

/// The stack's sheets as a contact surface, for the outward normals: on a thin sheet both
/// sides cancel (none); a stack without triangles gives none at all.
struct StackSurface {
  ContactSurface surface;
  VertexTriangles around;
  explicit StackSurface(const Stack& s) {
    if (s.triangles.empty()) return;
    surface = make_contact_surface(s.triangles);
    around = vertex_triangles(surface);
  }
  DcrSurface dcr() const { return surface.triangles.empty() ? DcrSurface{} : DcrSurface{&surface, &around}; }
};

DcrResult run(Stack& s, const DcrOptions& options, std::span<const ContactPair> mine) {
  DcrScratch scratch;
  const StackSurface surface(s);
  return resolve_contacts(mine, s.x_new, s.x_old, s.v, s.inv_mass, 1.0, options, surface.dcr(), scratch);
}

DcrResult run(Stack& s, const DcrOptions& options) { return run(s, options, s.pairs); }

struct Totals {
  Vec3 p = Vec3::Zero(), L = Vec3::Zero();
  double kinetic = 0, p_scale = 0, L_scale = 0;
};

Totals totals(const Stack& s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
  Totals t;
  for (size_t i = 0; i < v.size(); ++i) {
    if (s.inv_mass[i] == 0) continue;
    const double m = 1 / s.inv_mass[i];
    t.p += m * v[i];
    t.L += m * x[i].cross(v[i]);
    t.kinetic += 0.5 * m * v[i].squaredNorm();
    t.p_scale += m * v[i].norm();
    t.L_scale += m * x[i].norm() * v[i].norm();
  }
  return t;
}

}  // namespace

class DcrStack : public ::testing::TestWithParam<bool> {};

TEST_P(DcrStack, OnFixedGroundIsResolved) {
  Stack s = make_stack(5, 5, true, 1, GetParam());
  ASSERT_GT(count_penetrations(s, s.x_new), 0);
  const std::vector<Vec3> x0 = s.x_new, v0 = s.v;
  const DcrResult r = run(s, {0.5, 0.3, 1e-6, 200});
  EXPECT_FALSE(r.capped);
  EXPECT_GT(r.contacts, 0);
  EXPECT_GE(r.sweeps, 2);
  EXPECT_GT(r.dissipated.value(), 0);
  EXPECT_EQ(count_penetrations(s, s.x_new), 0);
  for (size_t i = 0; i < s.x_new.size(); ++i)
    if (s.inv_mass[i] == 0) {
      EXPECT_EQ(s.x_new[i], x0[i]);
      EXPECT_EQ(s.v[i], v0[i]);
    }
  RecordProperty("pairs", static_cast<int>(s.pairs.size()));
  RecordProperty("contacts", r.contacts);
  RecordProperty("sweeps", r.sweeps);
}

INSTANTIATE_TEST_SUITE_P(DcrSweep, DcrStack, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "ThinSheets" : "ThickBodies"; });

// The order of resolution (contact/dcr_order.hpp): whatever pairs run together on threads
// (or ranks), each node sees its pairs in key order, so the result is that of resolving the
// pairs found in a round one by one, sorted by key. The reference here does exactly that,
// serially, detecting every pair in every round; resolve_contacts, on 4 threads, must give
// its bits.
TEST(DcrSweep, ResolutionIsAOneByOnePassInKeyOrder) {
  const Stack initial = make_stack(5, 6, true, 9, true);
  const DcrOptions options{0.5, 0.3, 1e-6, 200};
  const tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);
  Stack parallel = initial, serial = initial;
  tbb::task_arena arena(4);
  const DcrResult r = arena.execute([&] { return run(parallel, options); });
  ASSERT_FALSE(r.capped);

  const StackSurface surface(serial);
  TriangleNormals tn;
  if (surface.dcr().surface) tn = triangle_normals(surface.surface, serial.x_old);
  const DcrLaw law{options.restitution, options.friction, options.gap, options.placement};
  auto points = [&](const ContactPair& p, PairPoints& X_old, PairPoints& X_new, PairPoints& V) {
    for (int c = 0; c < 4; ++c) {
      X_old.col(c) = serial.x_old[p.nodes[c]];
      X_new.col(c) = serial.x_new[p.nodes[c]];
      V.col(c) = serial.v[p.nodes[c]];
    }
  };
  ContactPairs overlapping;
  for (const ContactPair& p : serial.pairs) {
    PairPoints X_old, X_new, V;
    points(p, X_old, X_new, V);
    if (pair_boxes_overlap(p.kind, X_old, X_new)) overlapping.push_back(p);
  }
  int rounds = 0;
  ExactSum dissipated;
  while (true) {
    ++rounds;
    std::vector<std::pair<DcrKey, ContactPair>> found;
    for (const ContactPair& p : overlapping) {
      PairPoints X_old, X_new, V;
      points(p, X_old, X_new, V);
      const auto kind = p.kind == ContactPair::VertexFace ? DcrPairKind::VertexFace : DcrPairKind::EdgeEdge;
      if (dcr_detect(kind, X_old, X_new, pair_normals(p, surface.dcr(), tn)).penetrating) {
        std::array<std::uint64_t, 4> ids;
        for (int c = 0; c < 4; ++c) ids[c] = static_cast<std::uint64_t>(p.nodes[c]);
        found.emplace_back(dcr_key(p.kind, ids, rounds - 1), p);
      }
    }
    if (found.empty()) break;
    std::sort(found.begin(), found.end());
    for (const auto& [key, p] : found) {
      PairPoints X_old, X_new, V;
      points(p, X_old, X_new, V);
      PairWeights w;
      for (int c = 0; c < 4; ++c) w[c] = serial.inv_mass[p.nodes[c]];
      const auto kind = p.kind == ContactPair::VertexFace ? DcrPairKind::VertexFace : DcrPairKind::EdgeEdge;
      const DcrPairResponse out =
          dcr_resolve_pair(kind, X_old, X_new, V, pair_normals(p, surface.dcr(), tn), w, law, 0.5);
      if (!out.active) continue;
      dissipated += out.impulse.dissipated;
      for (int c = 0; c < 4; ++c) {
        serial.x_new[p.nodes[c]] = X_new.col(c);
        serial.v[p.nodes[c]] = V.col(c);
      }
    }
  }
  EXPECT_GT(r.contacts, 0);
  EXPECT_EQ(r.sweeps, rounds);
  EXPECT_EQ(r.dissipated.value(), dissipated.value());
  EXPECT_EQ(std::memcmp(parallel.x_new.data(), serial.x_new.data(), serial.x_new.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(parallel.v.data(), serial.v.data(), serial.v.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(count_penetrations(parallel, parallel.x_new), 0);
}

TEST(DcrSweep, ElasticFrictionlessStackConservesMomentumAndEnergy) {
  Stack s = make_stack(5, 4, false, 3, true);
  const Totals before = totals(s, s.x_new, s.v);
  const DcrResult r = run(s, {1.0, 0.0, 1e-6, 200});
  const Totals after = totals(s, s.x_new, s.v);
  EXPECT_FALSE(r.capped);
  EXPECT_GT(r.contacts, 0);
  EXPECT_EQ(r.dissipated.value(), 0.0);
  EXPECT_LT((after.p - before.p).norm(), 1e-13 * before.p_scale);
  EXPECT_LT((after.L - before.L).norm(), 1e-12 * before.L_scale);
  // The kinetic energy: all but the projections' angular-momentum counterpart's work (booked
  // as contact_work), 0.29 % of it here, where the projections move nodes by up to a tenth
  // of an edge in one step.
  EXPECT_CLOSE(before.kinetic - after.kinetic, r.work.value(), 0, 1e-13 * before.kinetic);
  EXPECT_LT(std::abs(r.work.value()), 1e-2 * before.kinetic);
  RecordProperty("rel_linear_momentum_error", sci((after.p - before.p).norm() / before.p_scale));
  RecordProperty("rel_angular_momentum_error", sci((after.L - before.L).norm() / before.L_scale));
  RecordProperty("rel_counterpart_work", sci(r.work.value() / before.kinetic));
}

TEST(DcrSweep, DissipationMatchesTheKineticEnergyLost) {
  Stack s = make_stack(5, 4, false, 4, true);
  const Totals before = totals(s, s.x_new, s.v);
  const DcrResult r = run(s, {0.3, 0.4, 1e-6, 200});
  const Totals after = totals(s, s.x_new, s.v);
  EXPECT_FALSE(r.capped);
  EXPECT_GT(r.dissipated.value(), 0);
  EXPECT_LT((after.p - before.p).norm(), 1e-13 * before.p_scale);
  EXPECT_LT((after.L - before.L).norm(), 1e-12 * before.L_scale);
  EXPECT_CLOSE(before.kinetic - after.kinetic, r.dissipated.value() + r.work.value(), 0, 1e-13 * before.kinetic);
}

// Chains of pairs sharing nodes: the stacks collapse (thin sheets: a vertex pushed out of
// one contact into the next, many rounds), sliding (the bodies' tangential velocities) and
// spinning (a rigid spin of the whole stack about the origin added), every placement, with
// and without friction and restitution. Linear and angular momentum of the free stack are
// kept to 1e-12 of their scales at the state sum m x_new x v, and the kinetic energy lost is
// the dissipation plus the projections' counterpart work.
TEST(DcrSweep, CollapsingStacksKeepBothMomenta) {
  for (const bool thin : {false, true})
    for (const DcrPlacement placement : {DcrPlacement::End, DcrPlacement::Middle, DcrPlacement::Impact})
      for (const auto& [e, mu] : {std::pair{1.0, 0.0}, std::pair{0.5, 0.3}}) {
        SCOPED_TRACE(testing::Message() << "thin " << thin << ", placement " << static_cast<int>(placement) << ", e "
                                        << e << ", mu " << mu);
        Stack s = make_stack(5, 4, false, 11, thin);
        const Vec3 omega(0.01, -0.02, 0.015);
        for (size_t i = 0; i < s.v.size(); ++i) {
          s.v[i] += omega.cross(s.x_old[i]);
          s.x_new[i] = s.x_old[i] + s.v[i];
        }
        const Totals before = totals(s, s.x_new, s.v);
        const DcrResult r = run(s, {e, mu, 1e-6, 200, placement});
        const Totals after = totals(s, s.x_new, s.v);
        EXPECT_FALSE(r.capped);
        EXPECT_GT(r.contacts, 20);
        EXPECT_LT((after.p - before.p).norm(), 1e-12 * before.p_scale);
        EXPECT_LT((after.L - before.L).norm(), 1e-12 * before.L_scale);
        EXPECT_CLOSE(before.kinetic - after.kinetic, r.dissipated.value() + r.work.value(), 0,
                     1e-13 * before.kinetic);
        std::printf("thin %d placement %d e %.1f: %ld contacts, %d rounds, dL %.1e, work %.1e of K\n", thin,
                    static_cast<int>(placement), e, static_cast<long>(r.contacts), r.sweeps,
                    (after.L - before.L).norm() / before.L_scale, r.work.value() / before.kinetic);
      }
}

TEST(DcrSweep, IndependentImpactsConserveAngularMomentum) {
  // Separate vertex-face impacts (no shared nodes), sliding, with friction: the angular
  // momentum about the origin of the state (x_new, v) is unchanged to round-off.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Stack s;
  for (int k = 0; k < 50; ++k) {
    const Vec3 o(4.0 * k, 3 * u(rng), 3 * u(rng));
    const std::array<Vec3, 4> x{o + Vec3(0.3, 0.3, 0.1 + 0.05 * u(rng)), o, o + Vec3(1, 0.1 * u(rng), 0),
                                o + Vec3(0.1 * u(rng), 1, 0)};
    const Vec3 vp(0.2 * u(rng), 0.2 * u(rng), -0.5 + 0.1 * u(rng));
    const Index first = static_cast<Index>(s.x_old.size());
    for (int i = 0; i < 4; ++i) {
      const Vec3 vel = i == 0 ? vp : Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
      s.x_old.push_back(x[i]);
      s.x_new.push_back(x[i] + vel);
      s.v.push_back(vel);
      s.inv_mass.push_back(1 / (1.5 + u(rng)));
    }
    s.pairs.push_back({ContactPair::VertexFace, {first, first + 1, first + 2, first + 3}});
  }
  const Totals before = totals(s, s.x_new, s.v);
  const DcrResult r = run(s, {1.0, 0.5, 1e-6, 10});
  EXPECT_EQ(r.contacts, 50);
  EXPECT_EQ(r.sweeps, 2);
  const Totals after = totals(s, s.x_new, s.v);
  EXPECT_LT((after.p - before.p).norm(), 1e-13 * before.p_scale);
  EXPECT_LT((after.L - before.L).norm(), 1e-13 * before.L_scale);
  EXPECT_CLOSE(before.kinetic - after.kinetic, r.dissipated.value() + r.work.value(), 0, 1e-13 * before.kinetic);
  RecordProperty("rel_angular_momentum_error", sci((after.L - before.L).norm() / before.L_scale));
}

TEST(DcrSweep, CapIsReported) {
  Stack s = make_stack(4, 4, true, 6);
  const DcrResult r = run(s, {1.0, 0.0, 1e-6, 1});
  EXPECT_EQ(r.sweeps, 1);
  EXPECT_TRUE(r.capped);
  ASSERT_TRUE(r.unresolved.has_value());
  EXPECT_TRUE(std::binary_search(s.pairs.begin(), s.pairs.end(), *r.unresolved));
}

TEST(DcrSweep, BitwiseIdenticalForAnyThreadCount) {
  const Stack initial = make_stack(5, 6, true, 7, true);
  const tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);  // even on fewer cores
  std::vector<Stack> runs;
  std::vector<DcrResult> results;
  for (const int threads : {1, 2, 4}) {
    Stack s = initial;
    tbb::task_arena arena(threads);
    results.push_back(arena.execute([&] { return run(s, {0.4, 0.3, 1e-6, 1000}); }));
    runs.push_back(std::move(s));
  }
  for (size_t k = 1; k < runs.size(); ++k) {
    EXPECT_EQ(std::memcmp(runs[k].x_new.data(), runs[0].x_new.data(), runs[0].x_new.size() * sizeof(Vec3)), 0);
    EXPECT_EQ(std::memcmp(runs[k].v.data(), runs[0].v.data(), runs[0].v.size() * sizeof(Vec3)), 0);
    EXPECT_EQ(results[k].dissipated.value(), results[0].dissipated.value());
    EXPECT_EQ(results[k].contacts, results[0].contacts);
    EXPECT_EQ(results[k].sweeps, results[0].sweeps);
  }
  EXPECT_EQ(count_penetrations(runs[0], runs[0].x_new), 0);
}

TEST(DcrSweep, RejectsInconsistentInput) {
  Stack s = make_stack(2, 2, true, 8);
  DcrScratch scratch;
  std::vector<double> short_inv_mass(s.inv_mass.begin(), s.inv_mass.end() - 1);
  EXPECT_THROW(resolve_contacts(s.pairs, s.x_new, s.x_old, s.v, short_inv_mass, 1.0, {}, {}, scratch), Error);
  const ContactPairs beyond{{ContactPair::VertexFace, {0, 1, 2, static_cast<Index>(s.x_new.size())}}};
  EXPECT_THROW(resolve_contacts(beyond, s.x_new, s.x_old, s.v, s.inv_mass, 1.0, {}, {}, scratch), Error);
  // A bad pair after many good ones (the check runs in the detection's chunks): named by its
  // index, and no state changed.
  ASSERT_FALSE(s.pairs.empty());
  ContactPairs many;
  while (many.size() < 1000) many.insert(many.end(), s.pairs.begin(), s.pairs.end());
  const size_t bad = many.size();
  many.push_back({ContactPair::EdgeEdge, {0, -1, 2, 3}});
  const std::vector<Vec3> x_new = s.x_new, v = s.v;
  try {
    resolve_contacts(many, s.x_new, s.x_old, s.v, s.inv_mass, 1.0, {}, {}, scratch);
    ADD_FAILURE() << "no error for a node of -1";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("node -1 of pair " + std::to_string(bad)), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.x_new, x_new);
  EXPECT_EQ(s.v, v);
}
