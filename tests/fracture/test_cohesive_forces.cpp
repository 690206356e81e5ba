// Cohesive element forces: a two-tet bar pulled apart through its one facet,
// the whole pipeline (criterion -> insertion -> copies -> cohesive forces ->
// release -> fragments), with the energy dissipated checked against Gc x area.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "expect_close.hpp"
#include "fracture/cohesive_elements.hpp"
#include "fracture/fragments.hpp"
#include "fracture_fixtures.hpp"
#include "kernels/neo_hookean.hpp"
#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

using namespace shatter;

namespace {

/// Two tets sharing the facet (0,1,2) in the plane z = 0 (area 1/2); apex 3
/// above, apex 4 below.
Mesh two_tets() {
  Mesh m;
  m.order = 1;
  m.reference = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.2, 0.3, 1),
                 Vec3(0.3, 0.2, -1)};
  m.node_gid = {1, 2, 3, 4, 5};
  m.node_body = {0, 0, 0, 0, 0};
  m.conn = {0, 1, 2, 3, 0, 2, 1, 4};
  m.elem_gid = {1, 2};
  m.elem_body = {0, 0};
  m.elem_material = {0, 0};
  m.build_node_elements();
  return m;
}

/// The same two elements as TET10: mid-edge nodes added once per edge.
Mesh two_tet10s() {
  const Mesh linear = two_tets();
  Mesh m = linear;
  m.order = 2;
  m.conn.clear();
  std::map<std::array<Index, 2>, Index> mid;
  for (Index e = 0; e < 2; ++e) {
    const Index* c = linear.element(e);
    std::array<Index, 10> nodes;
    for (int a = 0; a < 4; ++a) nodes[a] = c[a];
    for (int i = 0; i < 6; ++i) {
      const Index a = c[kTet10Edges[i][0]], b = c[kTet10Edges[i][1]];
      const auto key = std::array<Index, 2>{std::min(a, b), std::max(a, b)};
      if (!mid.count(key)) {
        mid[key] = m.num_nodes();
        m.reference.push_back(0.5 * (linear.reference[a] + linear.reference[b]));
        m.node_gid.push_back(m.num_nodes());
        m.node_body.push_back(0);
      }
      nodes[4 + i] = mid[key];
    }
    m.conn.insert(m.conn.end(), nodes.begin(), nodes.end());
  }
  m.build_node_elements();
  return m;
}

/// The two-element mesh with its facet (face 3 of element 0, (0,2,1)) made
/// cohesive, law sigma_c = 100 Pa, Gc = 1 J/m^2, k_p = 1e7 Pa/m and a given beta.
struct JoinedPair {
  Mesh m;
  Topology t;
  CohesiveElements coh;
  CohesiveLaw law;
  std::vector<std::optional<CohesiveLaw>> laws;
};

JoinedPair joined_pair(const Mesh& start, double beta) {
  JoinedPair p{start, {}, {}, make_cohesive_law(100.0, 1.0, beta, 1.0e7), {}};
  p.t = build_topology(p.m);
  p.laws = test::one_law(p.law);
  insert_cohesive_elements(p.m, p.t, p.coh, std::vector<Index>{p.t.elem_facet[3]});
  return p;
}

/// Calls f(m, t, coh, law, laws, sign) of a JoinedPair for TET4 and TET10,
/// beta 0.6, 1 and 1.5, sign +1 and -1.
template <class F>
void for_each_joined_pair(F f) {
  for (const Mesh& start : {two_tets(), two_tet10s()})
    for (double beta : {0.6, 1.0, 1.5})
      for (double sign : {1.0, -1.0}) {
        JoinedPair p = joined_pair(start, beta);
        f(p.m, p.t, p.coh, p.law, FractureLaws(p.laws), sign);
      }
}

/// Open the facet of the two-element mesh by translating side 1 rigidly along
/// `direction` up to 1.2 delta_c in `steps` steps; returns the work done on the
/// cohesive element (trapezoidal rule on f . dx) and checks the total force on
/// each side against the law at every step.
double prescribed_opening_work(Mesh m, const CohesiveLaw& law, const Vec3& direction, int steps,
                               CohesiveEnergy& energy) {
  Topology t = build_topology(m);
  CohesiveElements coh;
  const auto laws = test::one_law(law);
  insert_cohesive_elements(m, t, coh, std::vector<Index>{t.elem_facet[3]});
  const int k = m.order == 1 ? 3 : 6;
  std::vector<bool> side1(m.num_nodes(), false);
  for (int j = 0; j < k; ++j) side1[coh.side_nodes[6 + j]] = true;
  const Vec3 n(0, 0, -1);  // outward of element 0 through its face (0,2,1)
  const double area = 0.5;
  std::vector<Vec3> x, f_old;
  double work = 0;
  // Start just after insertion (lambda = 1e-9 delta_c), where the extrinsic
  // traction is already sigma_c, so the trapezoidal rule is exact on the envelope.
  for (int s = 0; s <= steps; ++s) {
    const double lambda = 1.2 * law.delta_c * std::max(1e-9, double(s) / steps);
    std::vector<Vec3> x_new = m.reference;
    for (Index i = 0; i < m.num_nodes(); ++i)
      if (side1[i]) x_new[i] += lambda * direction;
    std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
    energy = cohesive_forces(m, t, coh, laws, x_new, f);
    Vec3 total1 = Vec3::Zero();
    for (Index i = 0; i < m.num_nodes(); ++i) {
      if (s > 0) work += 0.5 * (f_old[i] + f[i]).dot(x_new[i] - x[i]);
      if (side1[i]) total1 += f[i];
    }
    // A uniform opening: every point carries the same traction (checked past
    // the first point, whose opening is at the round-off of the positions).
    const Vec3 expected = area * cohesive_traction(law, lambda * direction, n, 0.0).traction;
    if (s > 0) {
      EXPECT_LT((total1 - expected).norm(), 1e-11 * law.sigma_c * area);
    }
    x = x_new;
    f_old = f;
  }
  return work;
}

}  // namespace

TEST(CohesiveForces, PulledFacetDissipatesGcTimesArea) {
  Mesh m = two_tets();
  ASSERT_NO_THROW(validate_mesh(m, "two tets"));
  Topology t = build_topology(m);
  CohesiveElements coh;
  const NeoHookean mat = NeoHookean::from_young_poisson(1.0e4, 0.25, 1.0);
  const double gc = 1.0;
  const CohesiveLaw law = make_cohesive_law(100.0, gc, 0.8, 1.0e7);
  const auto laws = test::one_law(law);

  std::vector<Vec3> x = m.reference, v(m.num_nodes(), Vec3::Zero());
  std::vector<double> mass = test::lumped_masses(m, mat.density);
  const double v_pull = 0.01;                // m/s, each apex: slow against c = 115 m/s
  const double dt = 1.0e-4, damping = 20.0;  // 1/s, mass-proportional, on the free nodes
  std::vector<Vec3> f, f_coh;
  std::vector<double> stress;
  double work = 0;  // work done on the cohesive element, J
  bool inserted = false, released = false;
  CohesiveEnergy energy;
  auto apex = [&](Index n) { return m.node_gid[n] == 4 || m.node_gid[n] == 5; };

  auto compute_forces = [&]() {
    f.assign(m.num_nodes(), Vec3::Zero());
    f_coh.assign(m.num_nodes(), Vec3::Zero());
    stress.assign(9 * m.num_elements(), 0.0);
    for (Index e = 0; e < m.num_elements(); ++e) {
      const Index* c = m.element(e);
      const Tet4Reference ref = tet4_reference(m.reference[c[0]], m.reference[c[1]],
                                               m.reference[c[2]], m.reference[c[3]]);
      const Tet4Force fe =
          tet4_internal_force(x[c[0]], x[c[1]], x[c[2]], x[c[3]], ref.Dm_inv, ref.volume, mat);
      for (int a = 0; a < 4; ++a) f[c[a]] += fe.f.col(a);
      const Mat3 sigma = mat.cauchy_stress(
          tet4_deformation_gradient(x[c[0]], x[c[1]], x[c[2]], x[c[3]], ref.Dm_inv));
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(stress.data() + 9 * e) = sigma;
    }
    energy = cohesive_forces(m, t, coh, laws, x, f_coh);
    for (Index n = 0; n < m.num_nodes(); ++n) f[n] += f_coh[n];
  };

  compute_forces();
  int steps = 0;
  for (; steps < 400000 && !released; ++steps) {
    std::vector<Vec3> x_old = x, f_coh_old = f_coh;
    for (Index n = 0; n < m.num_nodes(); ++n) {
      if (apex(n))
        v[n] = Vec3(0, 0, m.node_gid[n] == 4 ? v_pull : -v_pull);
      else
        v[n] += 0.5 * dt * (-f[n] / mass[n] - damping * v[n]);
      x[n] += dt * v[n];
    }
    compute_forces();
    for (Index n = 0; n < m.num_nodes(); ++n) {
      if (!apex(n)) v[n] += 0.5 * dt * (-f[n] / mass[n] - damping * v[n]);
      work += 0.5 * (f_coh_old[n] + f_coh[n]).dot(x[n] - x_old[n]);
    }
    if (!inserted) {
      const std::vector<Index> critical = critical_facets(m, t, x, stress, 9, laws);
      if (!critical.empty()) {
        ASSERT_EQ(critical.size(), 1u);
        const Insertion ins = insert_cohesive_elements(m, t, coh, critical);
        ASSERT_EQ(ins.new_nodes.size(), 3u);  // all three facet nodes split
        ASSERT_EQ(ins.crack_faces.size(), 2u);
        x.resize(m.num_nodes());
        v.resize(m.num_nodes());
        for (const auto& [copy, parent] : ins.new_nodes) {
          x[copy] = x[parent];
          v[copy] = v[parent];
        }
        mass = test::lumped_masses(m, mat.density);
        compute_forces();
        inserted = true;
      }
    } else {
      released = release_debonded(t, coh) == 1;
    }
  }
  ASSERT_TRUE(inserted);
  ASSERT_TRUE(released) << "after " << steps << " steps";
  const double area = 0.5, expected = gc * area;
  EXPECT_CLOSE(energy.dissipated.value(), expected, 1e-12, 0);
  EXPECT_EQ(energy.stored.value(), 0.0);
  // The work of the cohesive forces over the history, an independent check of
  // forces against the law's energy.
  EXPECT_CLOSE(work, expected, 0.01, 0);
  const Fragments fr = find_fragments(m, t, x, v, mass);
  ASSERT_EQ(fr.count(), 2);
  EXPECT_GT(fr.stats[0].velocity.z(), 0.0);  // element 1 (apex 4, above) moves up
  EXPECT_LT(fr.stats[1].velocity.z(), 0.0);
  // The crack surface: the facet, debonded and between the two fragments; all
  // the dissipated energy is in it. Joined again, it is no longer between fragments.
  const CrackArea a = crack_area(m, t, coh, laws, fr.elem_fragment);
  EXPECT_CLOSE(a.debonded.value(), area, 1e-15, 0);
  EXPECT_CLOSE(a.between_fragments.value(), area, 1e-15, 0);
  EXPECT_CLOSE(a.debonded_dissipated.value(), energy.dissipated.value(), 1e-15, 0);
  const std::vector<Index> one_piece(m.num_elements(), 0);
  EXPECT_EQ(crack_area(m, t, coh, laws, one_piece).between_fragments.value(), 0.0);
  // Freed, the facet exerts no force even when its faces are pushed through
  // each other (the pieces it separated can fly anywhere), and keeps Gc x area.
  for (Index i = 0; i < m.num_nodes(); ++i) x[i] = m.reference[i];
  for (int j = 0; j < 3; ++j) x[coh.side_nodes[6 + j]] += Vec3(0.3, 0.1, 0.2);
  std::vector<Vec3> f_free(m.num_nodes(), Vec3::Zero());
  const CohesiveEnergy e_free = cohesive_forces(m, t, coh, laws, x, f_free);
  for (const Vec3& fi : f_free) EXPECT_EQ(fi.norm(), 0.0);
  EXPECT_EQ(e_free.stored.value(), 0.0);
  EXPECT_CLOSE(e_free.dissipated.value(), expected, 1e-15, 0);
  // A rank whose share is empty (no cohesive element around its nodes)
  // computes and counts nothing: not every element.
  const CohesiveShare none{{}, {}, false};
  const CohesiveEnergy e_none = cohesive_forces(m, t, coh, laws, x, f_free, none);
  EXPECT_EQ(e_none.dissipated.value(), 0.0);
  EXPECT_TRUE(crack_area(m, t, coh, laws, one_piece, none).debonded.value() == 0.0);
}

TEST(CohesiveForces, PrescribedMixedOpeningWorkIsGcTimesAreaTet4AndTet10) {
  const CohesiveLaw law = make_cohesive_law(100.0, 1.0, 0.7, 1.0e7);
  const Vec3 n(0, 0, -1), s = Vec3(1, 2, 0).normalized();
  for (const Mesh& m : {two_tets(), two_tet10s()})
    for (double angle : {0.0, 0.6, 1.2}) {
      // Unit effective opening per unit lambda.
      const Vec3 direction = std::cos(angle) * n + std::sin(angle) / law.beta * s;
      CohesiveEnergy energy;
      const double work = prescribed_opening_work(m, law, direction, 2400, energy);
      EXPECT_CLOSE(work, 0.5 * law.fracture_energy(), 1e-8, 0)
          << "order " << m.order << " angle " << angle;
      EXPECT_CLOSE(energy.dissipated.value(), 0.5 * law.fracture_energy(), 1e-12, 0);
    }
}

TEST(CohesiveForces, Tet10UniformOpeningLoadsOnlyMidEdgeNodes) {
  // Integral of the 6-node facet shape functions: 0 at corners, A/3 at mid-edges.
  Mesh m = two_tet10s();
  Topology t = build_topology(m);
  CohesiveElements coh;
  const CohesiveLaw law = make_cohesive_law(100.0, 1.0, 1.0, 1.0e7);
  insert_cohesive_elements(m, t, coh, std::vector<Index>{t.elem_facet[3]});
  std::vector<Vec3> x = m.reference;
  for (int j = 0; j < 6; ++j) x[coh.side_nodes[6 + j]] += 0.25 * law.delta_c * Vec3(0, 0, -1);
  std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
  cohesive_forces(m, t, coh, test::one_law(law), x, f);
  const double t_eff = cohesive_envelope(law, 0.25 * law.delta_c), area = 0.5;
  for (int j = 0; j < 6; ++j) {
    const Vec3 expected = j < 3 ? Vec3::Zero() : Vec3(0, 0, -t_eff * area / 3);
    EXPECT_LT((f[coh.side_nodes[6 + j]] - expected).norm(), 1e-12 * t_eff * area);
    EXPECT_LT((f[coh.side_nodes[j]] + expected).norm(), 1e-12 * t_eff * area);
  }
}

TEST(CohesiveForces, ForcesAreEqualAndOpposite) {
  JoinedPair p = joined_pair(two_tets(), 0.6);
  const Mesh& m = p.m;
  ASSERT_EQ(m.num_nodes(), 8);
  std::vector<Vec3> x = m.reference;
  // A mixed opening with a rotation of side 1, then a compressed one.
  for (double sign : {1.0, -1.0}) {
    for (Index n = 5; n < 8; ++n)
      x[n] = m.reference[n] + 1e-3 * Vec3(0.3 * n, -0.2, sign * (0.5 + 0.1 * n));
    std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
    cohesive_forces(m, p.t, p.coh, p.laws, x, f);
    Vec3 sum = Vec3::Zero();
    double scale = 0;
    for (const Vec3& fi : f) {
      sum += fi;
      scale += fi.norm();
    }
    EXPECT_GT(scale, 0.0);
    EXPECT_LT(sum.norm(), 1e-14 * scale);
  }
}

TEST(CohesiveForces, EigenvalueBoundHoldsAndIsTight) {
  // The stiffness K of the cohesive forces by central differences on two
  // elements joined by one cohesive facet, unloading from delta_max =
  // delta_u, where the secant is k_p and the bounded part of the traction
  // vanishes (kernels/cohesive.hpp), in tension and in compression:
  // the largest eigenvalue of M^-1/2 K M^-1/2 stays below
  // cohesive_eigenvalue_bound, which the stable step adds to the elements'
  // omega^2, and the bound is not loose.
  for_each_joined_pair([](Mesh& m, Topology& t, CohesiveElements& coh, const CohesiveLaw& law,
                          FractureLaws laws, double sign) {
    const std::vector<double> mass = test::lumped_masses(m, 1000.0);
    const double bound = cohesive_eigenvalue_bound(m, t, coh, laws, mass);
    // A state just past delta_u (secant K = envelope / delta_max = k_p to
    // round-off, t(0) = 0), then side 1 opened by a fraction of it along a
    // mixed direction.
    const double delta_u = law.sigma_c / (law.penalty + law.sigma_c / law.delta_c) * (1 + 1e-9);
    std::fill(coh.delta_max.begin(), coh.delta_max.end(), delta_u);
    std::vector<Vec3> x = m.reference;
    const int k = m.order == 1 ? 3 : 6;
    for (int j = 0; j < k; ++j)
      x[coh.side_nodes[6 + j]] += 0.2 * delta_u * Vec3(0.3, -0.2, -sign);
    const Index ndof = 3 * m.num_nodes();
    Eigen::MatrixXd K(ndof, ndof);
    const double h = 1e-4 * delta_u;
    for (Index d = 0; d < ndof; ++d) {
      std::vector<Vec3> xp = x, xm = x, fp(m.num_nodes(), Vec3::Zero()),
                        fm(m.num_nodes(), Vec3::Zero());
      xp[d / 3][d % 3] += h;
      xm[d / 3][d % 3] -= h;
      CohesiveElements cp = coh, cm = coh;
      cohesive_forces(m, t, cp, laws, xp, fp);
      cohesive_forces(m, t, cm, laws, xm, fm);
      for (Index r = 0; r < ndof; ++r)
        K(r, d) =
            (fp[r / 3][r % 3] - fm[r / 3][r % 3]) / (2 * h) / std::sqrt(mass[r / 3] * mass[d / 3]);
    }
    const Eigen::MatrixXd S = 0.5 * (K + K.transpose());
    const double largest =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(S).eigenvalues().cwiseAbs().maxCoeff();
    SCOPED_TRACE(testing::Message() << "order " << m.order << " beta " << law.beta << " sign "
                                    << sign << ": largest " << largest << ", bound " << bound);
    EXPECT_LE(largest, bound * (1 + 1e-6));
    EXPECT_GE(largest, 0.25 * bound);
  });
}

// The nodal forces are the gradient of the cohesive energy at a fixed state,
// the variation of the current normal included: central differences of the
// stored energy (unloading, so delta_max stays), for beta != 1, openings in
// tension and in compression, side 1 turned against side 0. And, the energy
// being invariant under rotations, they exert no net torque about any point
// (the term of the normal's variation balances Delta x T).
TEST(CohesiveForces, ForcesAreTheEnergyGradientAndExertNoTorque) {
  for_each_joined_pair([](Mesh& m, Topology& t, CohesiveElements& coh, const CohesiveLaw& law,
                          FractureLaws laws, double sign) {
    const int k = m.order == 1 ? 3 : 6;
    std::vector<Vec3> x = m.reference;
    std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
    // Load past the elastic rise (opening 0.5 delta_c, n = -z), then unload to
    // a turned, less open (sign 1) or closed (sign -1) configuration away
    // from the origin.
    for (int j = 0; j < k; ++j) x[coh.side_nodes[6 + j]] += 0.5 * law.delta_c * Vec3(0.6, 0, -0.8);
    cohesive_forces(m, t, coh, laws, x, f);
    const Mat3 turn = Eigen::AngleAxisd(0.001, Vec3(0.3, 1, 0.2).normalized()).toRotationMatrix();
    const Vec3 offset(2.0, -1.0, 0.5);
    for (Index i = 0; i < m.num_nodes(); ++i) x[i] = m.reference[i] + offset;
    for (int j = 0; j < k; ++j) {
      Vec3& xj = x[coh.side_nodes[6 + j]];
      xj = offset + turn * (xj - offset) + 0.1 * law.delta_c * Vec3(0.5, -0.3, -sign * 0.4);
    }
    auto energy = [&](const std::vector<Vec3>& y, std::vector<Vec3>& force) {
      CohesiveElements state = coh;
      std::fill(force.begin(), force.end(), Vec3::Zero());
      const CohesiveEnergy e = cohesive_forces(m, t, state, laws, y, force);
      EXPECT_EQ(state.delta_max, coh.delta_max) << "the probe reloaded the law";
      return e.stored.value();
    };
    energy(x, f);
    double f_scale = 0;
    Vec3 torque = Vec3::Zero();
    double torque_scale = 0;
    for (Index i = 0; i < m.num_nodes(); ++i) {
      f_scale = std::max(f_scale, f[i].norm());
      torque += x[i].cross(f[i]);
      torque_scale += x[i].norm() * f[i].norm();
    }
    SCOPED_TRACE(testing::Message()
                 << "order " << m.order << " beta " << law.beta << " sign " << sign);
    ASSERT_GT(f_scale, 0.0);
    EXPECT_LT(torque.norm(), 1e-14 * torque_scale);
    const double h = 1e-7;
    std::vector<Vec3> scratch(m.num_nodes());
    double err = 0;
    for (Index i = 0; i < m.num_nodes(); ++i)
      for (int d = 0; d < 3; ++d) {
        std::vector<Vec3> xp = x, xm = x;
        xp[i][d] += h;
        xm[i][d] -= h;
        const double fd = (energy(xp, scratch) - energy(xm, scratch)) / (2 * h);
        err = std::max(err, std::abs(fd - f[i][d]));
      }
    EXPECT_LT(err, 1e-6 * f_scale);
  });
}

// A facet slid past delta_c while pressed shut is not freed: its compression
// penalty holds energy that would vanish from the ledger with it. Opened, it is.
TEST(CohesiveForces, DebondedFacetIsFreedOnlyOutOfCompression) {
  JoinedPair p = joined_pair(two_tets(), 1.0);
  const Mesh& m = p.m;
  Topology& t = p.t;
  CohesiveElements& coh = p.coh;
  const CohesiveLaw& law = p.law;
  const FractureLaws laws = p.laws;
  const Index facet = p.coh.facet[0];
  // n = -z (from element 0 above to element 1 below): +z on side 1 presses it shut.
  for (double dz : {0.1, -0.1}) {
    std::vector<Vec3> x = m.reference;
    for (int j = 0; j < 3; ++j) x[coh.side_nodes[6 + j]] += law.delta_c * Vec3(1.5, 0, dz);
    std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
    const CohesiveEnergy e = cohesive_forces(m, t, coh, laws, x, f);
    EXPECT_CLOSE(e.dissipated.value(), law.fracture_energy() * 0.5, 1e-14, 0);
    if (dz > 0) {
      EXPECT_GT(e.stored.value(), 0.0);
      EXPECT_EQ(release_debonded(t, coh), 0);
      EXPECT_EQ(t.facet_state[facet], FacetState::cohesive);
    } else {
      EXPECT_EQ(e.stored.value(), 0.0);
      EXPECT_EQ(release_debonded(t, coh), 1);
      EXPECT_EQ(t.facet_state[facet], FacetState::free);
    }
  }
}

// A chip hanging by a corner (the 1e3 /s structured ring, docs/validation.md):
// two of the facet's points opened past delta_c and came apart, one still
// holds; then side 1 turns half a turn about the in-plane axis through
// corner 0 and the middle of edge 1-2, so that its corners 1 and 2 swap
// places: the mid-surface collapses to nearly a line (area 1e-3 of the
// facet's), whose normal is meaningless, and one apart point lies 0.7 (35
// delta_c) "inside" along it. An apart point exerts nothing; the penalty
// there, amplified by the turning-normal term's 1 / area, made forces of
// 1e7 sigma_c A and inverted an element of the ring. The forces stay within
// what the bonded point can exert, sigma_c A.
TEST(CohesiveForces, PointsComeApartAndATwistedChipExertsNoPenalty) {
  JoinedPair p = joined_pair(two_tets(), 1.0);
  const CohesiveLaw& law = p.law;
  const Index* side0 = p.coh.side_nodes.data();
  const Index* side1 = side0 + 6;
  // n = -z (from element 0 above to element 1 below): -z on side 1 opens it.
  std::vector<Vec3> x = p.m.reference;
  for (int j : {1, 2}) x[side1[j]] += 1.5 * law.delta_c * Vec3(0, 0, -1);  // points 1.25, 1.25, 0.5 delta_c
  std::vector<Vec3> f(p.m.num_nodes(), Vec3::Zero());
  cohesive_forces(p.m, p.t, p.coh, p.laws, x, f);
  EXPECT_CLOSE(p.coh.delta_max[0], 0.5 * law.delta_c, 1e-12, 0);  // still holds
  EXPECT_EQ(p.coh.delta_max[1], kPointApart);
  EXPECT_EQ(p.coh.delta_max[2], kPointApart);
  EXPECT_EQ(release_debonded(p.t, p.coh), 0);  // not every point apart

  const double eps = 1e-3;
  x = p.m.reference;
  x[side1[1]] = p.m.reference[side0[2]] + eps * Vec3(0, 0, 1);
  x[side1[2]] = p.m.reference[side0[1]] - eps * Vec3(0, 0, 1);
  std::fill(f.begin(), f.end(), Vec3::Zero());
  const CohesiveEnergy e = cohesive_forces(p.m, p.t, p.coh, p.laws, x, f);
  const double area = 0.5;  // the facet (0,0,0), (1,0,0), (0,1,0)
  for (const Vec3& fi : f) EXPECT_LE(fi.norm(), law.sigma_c * area) << fi.transpose();
  EXPECT_EQ(e.stored.value(), 0.0);  // the bonded point is closed, on its secant: no energy
  EXPECT_CLOSE(e.dissipated.value(),
               area / 3 * (2 * law.fracture_energy() + 0.5 * law.sigma_c * 0.5 * law.delta_c), 1e-13, 0);
}

// Side 1 turned half a turn about the facet's centroid: the mid-surface collapses to
// a point and has no normal. The forces stay finite (and balanced).
TEST(CohesiveForces, CollapsedMidSurfaceGivesFiniteForces) {
  JoinedPair p = joined_pair(two_tets(), 1.0);
  std::vector<Vec3> x = p.m.reference;
  Vec3 centre = Vec3::Zero();
  for (int j = 0; j < 3; ++j) centre += x[p.coh.side_nodes[j]] / 3;
  for (int j = 0; j < 3; ++j) x[p.coh.side_nodes[6 + j]] = 2 * centre - x[p.coh.side_nodes[j]];
  std::vector<Vec3> f(p.m.num_nodes(), Vec3::Zero());
  const CohesiveEnergy e = cohesive_forces(p.m, p.t, p.coh, p.laws, x, f);
  Vec3 sum = Vec3::Zero();
  for (const Vec3& fi : f) {
    EXPECT_TRUE(fi.allFinite());
    sum += fi;
  }
  EXPECT_TRUE(std::isfinite(e.stored.value()));
  EXPECT_LT(sum.norm(), 1e-12);
}
