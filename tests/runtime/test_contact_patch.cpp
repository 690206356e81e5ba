// The contact patches (runtime/contact_patch.hpp) at 1, 2 and 3 ranks: over
// many steps of two bodies moving into each other (one spinning), the pairs
// the ranks check together are the pairs a search of the whole surface gives,
// each on exactly one rank, while every rank knows only its own nodes' states
// (the others' x(n+1) and v are NaN; their x(n) is what the rank held as x(n+1)
// at the end of the last step, and x(n+1) = x(n) + dt v, as in the time loop).
// The patch keeps the states it brings in arrays of its own: the part's rows of
// nodes outside its elements (no rigid body here) stay NaN, so the search never
// read them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "contact/candidates.hpp"
#include "mpi_environment.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/model.hpp"
#include "scene_text.hpp"

namespace shatter {
namespace {

/// A pair list as ints (kind, 4 nodes), for the ranks' gather.
std::vector<Index> flatten(const ContactPairs& pairs) {
  std::vector<Index> out;
  for (const ContactPair& p : pairs) {
    out.push_back(p.kind);
    out.insert(out.end(), p.nodes.begin(), p.nodes.end());
  }
  return out;
}

ContactPairs unflatten(const std::vector<Index>& in) {
  ContactPairs out;
  for (size_t k = 0; k + 5 <= in.size(); k += 5)
    out.push_back({static_cast<ContactPair::Kind>(in[k]), {in[k + 1], in[k + 2], in[k + 3], in[k + 4]}});
  return out;
}

TEST(ContactPatch, RanksTogetherCheckTheWholeSurfacesPairsOnce) {
  const Model m = build_model(test::scene_from_text("patch", test::sphere_and_box_contact_scene("patch")));
  const Decomposition dec(m, MPI_COMM_WORLD);
  ContactStage stage(m, ContactSpec{}, &dec);
  const Index n = m.mesh.num_nodes();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vec3> x_old = m.mesh.reference, x_new(n, Vec3::Constant(nan)), v(n), true_old = x_old, true_new(n);
  const std::vector<double> inv_mass(n, 0.0);  // DCR moves nothing: only the pair lists are compared
  const double step = 0.02 * stage.margin();
  const ContactSurface whole = build_contact_surface(m.mesh);  // on ranks the stage's is in surface vertex ids
  long nonempty = 0;
  for (int s = 0; s < 300; ++s) {
    const double angle = 2e-4 * s;
    for (Index i = 0; i < n; ++i) {
      const Vec3& X = m.mesh.reference[i];
      const Vec3 shift((s + 1) * step, 0, 0);
      const Vec3 to = m.mesh.node_body[i] == 0 ? Vec3(Vec3(X.x() * std::cos(angle) - X.y() * std::sin(angle),
                                                            X.x() * std::sin(angle) + X.y() * std::cos(angle), X.z()) +
                                                       shift)
                                                : Vec3(X - shift);
      // The central difference's states (dt = 1): x(n+1) = x(n) + v(n+1/2).
      const Vec3 true_v = to - true_old[i];
      true_new[i] = true_old[i] + 1.0 * true_v;
      // A rank knows the states of the nodes it owns, and x(n) of what it held at the end
      // of the last step.
      const bool mine = !dec.distributed() || dec.node_owner(i) == dec.rank();
      x_old[i] = mine ? true_old[i] : x_new[i];
      x_new[i] = mine ? true_new[i] : Vec3::Constant(nan);
      v[i] = mine ? true_v : Vec3::Constant(nan);
    }
    const DcrResult r = stage.apply(x_old, x_new, v, inv_mass, 1.0);
    // (With DCR moving nothing, the rounds reach their cap once bodies penetrate: the first
    // unresolved pair is named on every rank, its nodes' rows are not written.)
    EXPECT_EQ(stage.unresolved().has_value(), r.capped);
    for (Index i = 0; i < n && dec.distributed(); ++i) {
      const std::span<const int> ranks = dec.node_ranks(i);
      if (!std::binary_search(ranks.begin(), ranks.end(), dec.rank())) {
        ASSERT_TRUE(std::isnan(x_new[i].x()) && std::isnan(v[i].x()))
            << "step " << s << ": the stage wrote the part's row of node " << i << ", outside its elements";
      }
    }
    const ContactPairs fresh = find_candidates(whole, true_old, true_new);
    ContactPairs all = unflatten(dec.allgather(flatten(stage.active_pairs())));
    std::sort(all.begin(), all.end());
    ASSERT_EQ(all, fresh) << "step " << s << ": the ranks' pairs are not the whole surface's, once each";
    nonempty += !fresh.empty();
    true_old = true_new;
  }
  EXPECT_GT(nonempty, 100);
  EXPECT_LT(stage.searches(), 40) << "the candidates were not reused";
  if (dec.distributed()) {
    EXPECT_GT(stage.profile().state_bytes, 0) << "no state travelled";
  }
}

}  // namespace
}  // namespace shatter
