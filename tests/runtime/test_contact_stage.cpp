// Candidate reuse in the contact stage: over many steps of two meshed bodies
// moving into each other (and one spinning), the pairs DCR sees equal the list
// a fresh search of each step gives, while far fewer searches run. The bodies
// approach each other, so a pair can close by twice the reuse margin before a
// new search: an inflation of the search boxes below the margin fails here.
#include <gtest/gtest.h>

#include "contact/candidates.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/model.hpp"
#include "scene_text.hpp"

using namespace shatter;

TEST(ContactStage, ReusedCandidatesEqualAFreshSearchEveryStep) {
  const Model m = build_model(
      shatter::test::scene_from_text("stage", shatter::test::sphere_and_box_contact_scene("stage")));
  ContactStage stage(m, ContactSpec{});
  const Index n = m.mesh.num_nodes();
  std::vector<Vec3> x_old = m.mesh.reference, x_new(n), v(n, Vec3::Zero());
  const std::vector<double> inv_mass(n, 0.0);  // DCR moves nothing: only the pair lists are compared
  const double step = 0.02 * stage.margin();    // motion per step: many steps per search
  long nonempty = 0;
  for (int s = 0; s < 400; ++s) {
    const double angle = 2e-4 * s;
    for (Index i = 0; i < n; ++i) {
      const Vec3& X = m.mesh.reference[i];
      const Vec3 shift((s + 1) * step, 0, 0);  // the bodies approach at 2 x step: the hardest case
      if (m.mesh.node_body[i] == 0)
        x_new[i] = Vec3(X.x() * std::cos(angle) - X.y() * std::sin(angle),
                        X.x() * std::sin(angle) + X.y() * std::cos(angle), X.z()) + shift;
      else
        x_new[i] = X - shift;
    }
    stage.apply(x_old, x_new, v, inv_mass, 1.0);  // v = 0 with x moving: dt only scales the placement
    const ContactPairs fresh = find_candidates(stage.surface(), x_old, x_new);
    ASSERT_EQ(stage.active_pairs(), fresh) << "step " << s;
    nonempty += !fresh.empty();
    x_old = x_new;
  }
  EXPECT_GT(nonempty, 0);
  EXPECT_LT(stage.searches(), 40) << "the candidates were not reused";
}
