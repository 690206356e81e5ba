// The decomposition of the time loop (runtime/decomposition.hpp), run at 1, 2
// and 3 ranks: ownership covers everything once, a touched node has its whole
// star locally, ghost updates and shares deliver the owners' values, exact
// sums over the owned granules give the serial total, and the restricted element loop gives touched nodes the
// serial forces bit for bit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "mpi_environment.hpp"
#include "contact/surface.hpp"
#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/named_surface.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/fragment_labels.hpp"
#include "runtime/key_positions.hpp"
#include "runtime/model_part.hpp"
#include "runtime/model.hpp"
#include "runtime/row_blocks.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

namespace shatter {
namespace {

int world_rank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}
int world_size() {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  return ranks;
}
/// A file of rank 0's scenes folder, the same path on every rank and a path
/// of this run only.
std::filesystem::path run_file(const std::string& name) {
  int process = getpid();
  MPI_Bcast(&process, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return test::scenes_dir(process) / name;
}

const Model& box() {
  static const Model m = build_model(test::scene_from_text(
      "decomposition_box",
      test::steel_body_scene("decomposition_box",
                             "shape: box, size: [0.02, 0.016, 0.012], element_size: 0.0015, order: 1")));
  return m;
}

/// A value every rank can compute for node n, and a non-affine deformation.
Vec3 tag(Index n) { return Vec3(n, 0.5 * n + 1, -3.0 * n); }
Vec3 deformed(const Vec3& X) {
  return X + Vec3(0.01 * std::sin(60 * X.y()) * X.x(), 0.02 * X.x() * std::cos(40 * X.z()) - 0.01 * X.y(),
                  0.015 * X.z() * std::sin(50 * X.x()));
}

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(Vec3)) == 0; }

TEST(Decomposition, OwnershipCoversEverythingOnce) {
  const Model& m = box();
  const Decomposition d(m, MPI_COMM_WORLD);
  const Mesh& mesh = m.mesh;
  // Every granule belongs to one rank; the owned granules of all ranks add up.
  long owned = static_cast<long>(d.owned_granules().size()), total = 0;
  MPI_Allreduce(&owned, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, d.num_granules());
  for (Index g : d.owned_granules()) EXPECT_TRUE(d.owns_granule(g));
  // Home granules split the nodes: each node once, in the granule of its
  // first element, on that granule's owner.
  std::vector<int> seen(mesh.num_nodes(), 0);
  const auto granules = d.owned_granules();
  size_t homed = 0;
  for (size_t k = 0; k < granules.size(); ++k)
    for (Index n : d.home_nodes(k)) {
      EXPECT_EQ(mesh.node_elem[mesh.node_elem_offsets[n]] / ElementForces::kGranule, granules[k]);
      ++homed;
    }
  EXPECT_EQ(homed, d.owned_nodes().size());
  for (Index n : d.owned_nodes()) {
    seen[n] = 1;
    EXPECT_TRUE(d.owns_node(n));
  }
  MPI_Allreduce(MPI_IN_PLACE, seen.data(), static_cast<int>(seen.size()), MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  for (Index n = 0; n < mesh.num_nodes(); ++n) EXPECT_EQ(seen[n], 1) << "node " << n;
  // Owned elements: those of the owned granules.
  EXPECT_EQ(static_cast<Index>(d.owned_element_ids().size()), d.owned_elements());
  for (Index e : d.owned_element_ids()) EXPECT_TRUE(d.owns_element(e));
  // A touched node's whole star is local; an owned node is touched here.
  const auto local = d.local_elements();
  for (Index n : d.touched_nodes())
    for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
      EXPECT_TRUE(std::binary_search(local.begin(), local.end(), mesh.node_elem[p]));
  const auto touched = d.touched_nodes();
  for (Index n : d.owned_nodes()) EXPECT_TRUE(std::binary_search(touched.begin(), touched.end(), n));
  if (d.size() > 1) {
    EXPECT_LT(static_cast<Index>(local.size()), mesh.num_elements());
  }
}

TEST(Decomposition, GhostUpdateAndRowBlocksDeliverTheOwnersValues) {
  const Model& m = box();
  Decomposition d(m, MPI_COMM_WORLD);
  const Index nn = m.mesh.num_nodes();
  // Only touched nodes hold the right value; the rest is garbage.
  std::vector<Vec3> x(nn, Vec3::Constant(-7.0));
  for (Index n : d.touched_nodes()) x[n] = tag(n);
  d.begin_ghost_update(x);
  d.end_ghost_update(x);
  for (Index n : d.held_nodes()) EXPECT_TRUE(same_bits(x[n], tag(n))) << "node " << n;
  // Each node's row from its owner to the rank whose contiguous block holds
  // it (row_blocks.hpp: how checkpoints and fields are written).
  std::vector<Index> rows;
  std::vector<Vec3> values;
  for (Index n : d.touched_nodes())
    if (d.node_owner(n) == d.rank()) rows.push_back(n), values.push_back(tag(n));
  const std::vector<std::byte> block =
      to_row_blocks(rows, std::as_bytes(std::span<const Vec3>(values)), sizeof(Vec3), nn, MPI_COMM_WORLD);
  const RowBlock b = row_block(nn, d.rank(), d.size());
  ASSERT_EQ(block.size(), static_cast<size_t>(b.count) * sizeof(Vec3));
  for (Index i = 0; i < b.count; ++i) {
    Vec3 v;
    std::memcpy(v.data(), block.data() + static_cast<size_t>(i) * sizeof(Vec3), sizeof(Vec3));
    EXPECT_TRUE(same_bits(v, tag(b.first + i))) << "node " << b.first + i;
  }
  // allgather: the ranks' lists in rank order.
  const std::vector<Index> mine(d.rank() + 1, d.rank());
  const std::vector<Index> all = d.allgather(mine);
  ASSERT_EQ(static_cast<int>(all.size()), d.size() * (d.size() + 1) / 2);
  for (size_t i = 1; i < all.size(); ++i) EXPECT_LE(all[i - 1], all[i]);
}

TEST(Decomposition, KeyPositionsAreThoseInTheSortedUnion) {
  // Each rank contributes a scattered set of keys, some also contributed by
  // another rank, and asks for some of its own, some of others' and some
  // that nobody contributed; a sort of the whole union (every rank can make
  // it here) gives the expected positions.
  const Model& m = box();
  Decomposition d(m, MPI_COMM_WORLD);
  auto contributed_by = [](int r) {
    std::vector<GlobalId> keys;
    for (GlobalId k = 0; k < 400; ++k)
      if ((k * 7919 + r * 31) % 5 == 0 || k % 97 == r) keys.push_back(1000003 * (k % 13) + 3 * k + (k % 2));
    return keys;
  };
  std::vector<GlobalId> whole;
  for (int r = 0; r < d.size(); ++r) {
    const std::vector<GlobalId> keys = contributed_by(r);
    whole.insert(whole.end(), keys.begin(), keys.end());
  }
  std::sort(whole.begin(), whole.end());
  whole.erase(std::unique(whole.begin(), whole.end()), whole.end());
  const std::vector<GlobalId> mine = contributed_by(d.rank());
  std::vector<GlobalId> queried(mine.rbegin(), mine.rend());
  for (GlobalId k = 0; k < 200; ++k) queried.push_back(1000003 * (k % 17) + 5 * k + d.rank());
  const KeyPositions p = key_positions(mine, queried, d);
  EXPECT_EQ(p.total, static_cast<Index>(whole.size()));
  ASSERT_EQ(p.position.size(), queried.size());
  for (size_t q = 0; q < queried.size(); ++q) {
    const auto it = std::lower_bound(whole.begin(), whole.end(), queried[q]);
    const Index expected = it != whole.end() && *it == queried[q] ? static_cast<Index>(it - whole.begin()) : -1;
    EXPECT_EQ(p.position[q], expected) << "key " << queried[q];
  }
  // No key anywhere: nothing is named.
  const KeyPositions none = key_positions({}, queried, d);
  EXPECT_EQ(none.total, 0);
  EXPECT_EQ(std::count(none.position.begin(), none.position.end(), -1), static_cast<long>(queried.size()));
}

TEST(Decomposition, MinimaAndTheLeastPairTravelInOneMessage) {
  // The stable step's bounds and the worst element: element-wise minima, and the
  // least (key, index) pair, a tie on the key going to the smaller index.
  const Decomposition d(box(), MPI_COMM_WORLD);
  const int rank = world_rank(), size = world_size();
  // (A NaN on one rank wins on every rank, whatever the order the ranks combine in.)
  double values[3] = {1.0 + rank, -0.5 * rank, rank == size - 1 ? std::nan("") : 1.0};
  std::pair<double, long> least{rank == 0 ? 2.0 : -1.0, 10L - rank};
  d.min(values, least);
  EXPECT_EQ(values[0], 1.0);
  EXPECT_EQ(values[1], -0.5 * (size - 1));
  EXPECT_TRUE(std::isnan(values[2]));
  EXPECT_EQ(least.first, size == 1 ? 2.0 : -1.0);
  EXPECT_EQ(least.second, 10L - (size - 1));
  // -inf (the NaN marker) wins over any key; the sentinel index survives.
  std::pair<double, long> worst{rank == size - 1 ? -HUGE_VAL : 0.5, rank == size - 1 ? 3L : 1L};
  values[2] = 1.0;
  d.min(values, worst);
  EXPECT_EQ(worst.first, -HUGE_VAL);
  EXPECT_EQ(worst.second, 3L);
}

TEST(Decomposition, ExactSumsAndRestrictedForcesAreSerial) {
  const Model& m = box();
  const Decomposition d(m, MPI_COMM_WORLD);
  const Index nn = m.mesh.num_nodes();
  std::vector<Vec3> x(nn);
  for (Index n = 0; n < nn; ++n) x[n] = deformed(m.mesh.reference[n]);

  ElementForces serial(m), restricted(m);
  std::vector<Vec3> f_serial(nn), f(nn, Vec3::Constant(1e300));
  const ElementLoopResult whole = serial.compute(x, f_serial);
  if (d.distributed()) restricted.restrict_to(d.local_elements(), d.held_nodes(), d.ghost_only_nodes());
  const Index blocks = (m.mesh.num_elements() + ElementForces::kBlock - 1) / ElementForces::kBlock;
  EXPECT_EQ(restricted.early_blocks() + restricted.late_blocks(), blocks);
  // The ghost-only positions arrive between the two phases: until then they
  // are NaN, so an early block reading one would spoil the forces it scatters.
  std::vector<Vec3> x_late = x;
  for (Index n : d.ghost_only_nodes()) x_late[n] = Vec3::Constant(std::nan(""));
  bool between_ran = false;
  restricted.compute(x_late, f, {}, [&] {
    for (Index n : d.ghost_only_nodes()) x_late[n] = x[n];
    between_ran = true;
  });
  EXPECT_TRUE(between_ran);
  for (Index n : d.touched_nodes()) EXPECT_TRUE(same_bits(f[n], f_serial[n])) << "node " << n;

  // Owned granules' energies are the serial ones; summed exactly over the
  // ranks they give the serial total, bit for bit.
  ExactSum total;
  for (Index g : d.owned_granules()) {
    EXPECT_EQ(restricted.granule_energy(g), serial.granule_energy(g)) << "granule " << g;
    total += restricted.granule_energy(g);
  }
  d.sum({&total, 1});
  EXPECT_EQ(total.value(), whole.strain_energy);
  EXPECT_GT(total.value(), 0.0);
}

// The fragments merged across the ranks (FragmentLabels) are the serial
// ones (label_fragments): the same count and, for every owned element and
// every element sharing a facet with one, the same fragment id.
TEST(Decomposition, FragmentLabelsOnRanksAreTheSerialOnes) {
  const Model& m = box();
  const Decomposition d(m, MPI_COMM_WORLD);
  Topology topo = build_topology(m.mesh);
  const FragmentLabels labels(m, topo, d);
  for (int percent : {0, 30, 45, 60}) {
    // Free a pseudo-random share of the interior facets (by global id, the
    // same on every rank): from one piece through a percolating network to
    // many small pieces.
    for (Index f = 0; f < topo.num_facets(); ++f)
      if (topo.is_interior(f))
        topo.facet_state[f] = static_cast<int>((static_cast<std::uint64_t>(topo.facet_gid[f]) * 2654435761u) % 100) <
                                      percent
                                  ? FacetState::free
                                  : FacetState::intact;
    const Fragments serial = label_fragments(m.mesh, topo);
    const Fragments merged = labels.label(topo);
    ASSERT_EQ(merged.count(), serial.count()) << percent << " %";
    long checked = 0, across = 0;
    std::vector<int> fragment_rank(serial.count(), -1);
    for (Index e = 0; e < m.mesh.num_elements(); ++e) {
      int& r = fragment_rank[serial.elem_fragment[e]];
      if (r >= 0 && r != d.element_rank(e)) ++across;
      r = d.element_rank(e);
      if (merged.elem_fragment[e] < 0) continue;
      EXPECT_EQ(merged.elem_fragment[e], serial.elem_fragment[e]) << "element " << e << ", " << percent << " %";
      ++checked;
    }
    EXPECT_GE(checked, d.owned_elements());
    // On several ranks some fragments span ranks: the merge is exercised.
    if (d.distributed()) {
      EXPECT_GT(across, 0) << percent << " %";
    }
    if (percent == 0) {
      EXPECT_EQ(serial.count(), 1);
    }
    if (percent == 60) {
      EXPECT_GT(serial.count(), 100);
    }
  }
}

TEST(Decomposition, BuildModelOnSeveralRanksCutsTheWholeIntoParts) {
  // Rank 0 meshes and cuts the model; every rank gets its part (owned
  // elements and ghost layer), which holds the whole model's values and, in
  // the element loop, gives the whole model's forces bit for bit.
  const int ranks = world_size();
  const Scene scene = test::scene_from_text(
      "build_model_world",
      test::steel_body_scene("world", "shape: sphere, radius: 0.01, element_size: 0.0015, order: 2",
                             "    initial_velocity: [1, 0, 0]\n"
                             "    angular_velocity: [0, 0, 300]\n"));
  const Model part = build_model(scene, MPI_COMM_WORLD);
  const Model whole = build_model(scene);
  EXPECT_EQ(whole_fingerprint(part), model_fingerprint(whole));
  EXPECT_EQ(part.is_part(), ranks > 1);
  EXPECT_EQ(part.whole_elements(), whole.mesh.num_elements());
  EXPECT_EQ(part.whole_nodes(), whole.mesh.num_nodes());
  const int k = whole.mesh.nodes_per_element();
  for (Index e = 0; e < part.mesh.num_elements(); ++e) {
    const Index w = part.whole_element(e);
    EXPECT_EQ(part.mesh.elem_gid[e], whole.mesh.elem_gid[w]);
    EXPECT_EQ(part.element_volume[e], whole.element_volume[w]);
    for (int a = 0; a < k; ++a) EXPECT_EQ(part.whole_node(part.mesh.element(e)[a]), whole.mesh.element(w)[a]);
  }
  for (Index n = 0; n < part.mesh.num_nodes(); ++n) {
    const Index w = part.whole_node(n);
    EXPECT_TRUE(same_bits(part.mesh.reference[n], whole.mesh.reference[w]) &&
                same_bits(part.initial_velocity[n], whole.initial_velocity[w]))
        << "node " << n;
  }
  const Decomposition d(part, MPI_COMM_WORLD);
  EXPECT_EQ(static_cast<Index>(d.local_elements().size()), part.mesh.num_elements());
  EXPECT_EQ(static_cast<Index>(d.held_nodes().size()), part.mesh.num_nodes());
  long owned = d.owned_elements(), total = 0;
  MPI_Allreduce(&owned, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, whole.mesh.num_elements());
  if (ranks > 1) {
    EXPECT_LT(part.mesh.num_elements(), whole.mesh.num_elements());
  }

  // The ghost-only positions from their owners, then the forces: the whole model's.
  std::vector<Vec3> x(part.mesh.num_nodes(), Vec3::Constant(std::nan(""))), f(x.size());
  for (Index n : d.touched_nodes()) x[n] = deformed(part.mesh.reference[n]);
  d.begin_ghost_update(x);
  d.end_ghost_update(x);
  ElementForces forces(part);
  if (d.distributed()) forces.restrict_to(d.local_elements(), d.held_nodes(), d.ghost_only_nodes());
  forces.compute(x, f);
  std::vector<Vec3> X(whole.mesh.num_nodes()), F(X.size());
  for (Index n = 0; n < whole.mesh.num_nodes(); ++n) X[n] = deformed(whole.mesh.reference[n]);
  const ElementLoopResult serial = ElementForces(whole).compute(X, F);
  for (Index n : d.touched_nodes()) EXPECT_TRUE(same_bits(f[n], F[part.whole_node(n)])) << "node " << n;
  ExactSum energy;
  for (Index g : d.owned_granules()) energy += forces.granule_energy(g);
  d.sum({&energy, 1});
  EXPECT_EQ(energy.value(), serial.strain_energy);

  // A mesh that fails on rank 0 fails on every rank, as bad input.
  Scene bad = scene;
  bad.bodies[0].mesh_file = "/nonexistent/body.msh";
  EXPECT_THROW(build_model(bad, MPI_COMM_WORLD), InputError);
}

TEST(Decomposition, ContactPartsHoldTheSurfaceButNotItsNodesRows) {
  // A contact scene's part holds the rows of its elements' nodes and of the rigid
  // bodies' surface nodes only; of the whole surface it brings the rigid bodies' surface
  // nodes with their volume owners and the median edge, not the triangles nor the other
  // vertices.
  const Scene scene = test::scene_from_text(
      "contact_parts",
      "name: contact_parts\ntime: {end: 1.0e-5}\n"
      "materials:\n  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
      "bodies:\n"
      "  - {name: plate, material: steel, mesh: {shape: box, size: [0.06, 0.03, 0.01], center: [0, 0, -0.005], "
      "element_size: 0.003}}\n"
      "  - {name: block, material: steel, rigid: free, mesh: {shape: box, size: [0.01, 0.01, 0.01], "
      "center: [0, 0, 0.006], element_size: 0.003}, initial_velocity: [0, 0, -5]}\n"
      "contact: {}\n");
  const Model part = build_model(scene, MPI_COMM_WORLD);
  const Model whole = build_model(scene);
  if (!part.is_part()) return;
  const ContactSurface surface = build_contact_surface(whole.mesh);
  const Model::Part& p = part.part;
  EXPECT_EQ(p.surface_edge, median_edge_length(surface, whole.mesh.reference));
  const Decomposition d(part, MPI_COMM_WORLD);
  std::vector<char> in_element(part.mesh.num_nodes(), 0);
  for (Index e = 0; e < part.mesh.num_elements(); ++e)
    for (int a = 0; a < part.mesh.nodes_per_element(); ++a) in_element[part.mesh.element(e)[a]] = 1;
  std::vector<Index> rigid_held, touched;
  long surface_only_elsewhere = 0;
  for (const Index v : surface.vertices) {
    const Index n = part.local_node(v);
    const bool rigid = scene.bodies[whole.mesh.node_body[v]].has_rigid_state();
    if (n < 0) {
      EXPECT_FALSE(rigid) << "a rigid body's surface node " << v << " is not held";
      ++surface_only_elsewhere;
      continue;
    }
    EXPECT_TRUE(in_element[n] || rigid) << "surface node " << v << " held outside the elements";
    if (rigid) rigid_held.push_back(v);
    if (d.touches(n, d.rank())) touched.push_back(n);
  }
  EXPECT_GT(surface_only_elsewhere, 0) << "every part held every surface node";
  // The rigid bodies' surface nodes come with the part, with their owners; the part finds the
  // surface nodes it touches in its own mesh.
  ASSERT_EQ(p.rigid_surface_node, rigid_held);
  ASSERT_EQ(p.rigid_surface_owner.size(), rigid_held.size());
  for (size_t k = 0; k < rigid_held.size(); ++k)
    EXPECT_EQ(p.rigid_surface_owner[k], d.node_owner(part.local_node(rigid_held[k])));
  EXPECT_EQ(touched_surface_nodes(part, d), touched);
}

TEST(Decomposition, FracturePartsSplitNodesAsTheWholeModel) {
  // With fracture a part holds two ghost layers: every node of its owned and
  // first-layer elements has its whole star, splits as in the whole model,
  // and takes the whole model's index; the ranks touching it come from the
  // part's stars. Two rounds of insertion, the second splitting copies.
  const int ranks = world_size();
  const Scene scene = test::scene_from_text(
      "fracture_parts",
      "name: fracture_parts\ntime: {end: 1.0}\nmaterials:\n"
      "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3,\n"
      "          fracture: {strength: 3.0e8, energy: 100.0, beta: 1.0}}\n"
      "bodies:\n  - {name: b, material: steel, mesh: {shape: box, size: [0.02, 0.016, 0.012], element_size: 0.002}}\n");
  Model part = build_model(scene, MPI_COMM_WORLD);
  Model whole = build_model(scene);
  EXPECT_EQ(part.holds_two_layers(), ranks > 1);
  Decomposition d(part, MPI_COMM_WORLD);
  const Decomposition one(whole, MPI_COMM_SELF);
  // The whole model on the ranks, partitioned before any split as the parts were.
  Decomposition wd(whole, MPI_COMM_WORLD);
  FractureStage on_part(part, d), on_whole(whole, one);
  const Topology& wt = on_whole.topology();
  for (int round : {0, 1}) {
    std::vector<GlobalId> gids;
    for (Index f = 0; f < wt.num_facets(); ++f)
      if (wt.is_interior(f) && wt.facet_state[f] == FacetState::intact &&
          (static_cast<std::uint64_t>(wt.facet_gid[f]) * 2654435761u + round) % 100 < 12)
        gids.push_back(wt.facet_gid[f]);
    std::sort(gids.begin(), gids.end());
    on_whole.insert(gids, key_positions(gids, gids, one));
    const std::uint64_t revision = part.mesh.revision;
    const Index before = part.mesh.num_nodes();
    on_part.insert(gids, key_positions(gids, gids, d));
    part.bc_mask.resize(part.mesh.num_nodes(), 0);  // (no condition: the copies hold nothing)
    if (part.holds_two_layers()) {
      const Index added = number_split_nodes(part, before, revision, d);
      EXPECT_GT(added, 0) << "round " << round;
    }
    EXPECT_EQ(part.whole_nodes(), whole.mesh.num_nodes()) << "round " << round;
    EXPECT_EQ(part.mesh.revision, whole.mesh.revision) << "round " << round;
    EXPECT_EQ(on_part.cohesive_count(), on_whole.cohesive_count()) << "round " << round;
  }
  d.rebuild_nodes(on_part.side_nodes(), kCohesiveSlots);
  wd.rebuild_nodes(on_whole.side_nodes(), kCohesiveSlots);
  const int k = whole.mesh.nodes_per_element();
  long checked = 0;
  for (Index e : d.local_elements()) {
    const Index we = part.whole_element(e);
    for (int a = 0; a < k; ++a) {
      const Index n = part.mesh.element(e)[a], w = whole.mesh.element(we)[a];
      ASSERT_EQ(part.whole_node(n), w) << "element " << we << " node " << a;
      EXPECT_EQ(part.mesh.node_gid[n], whole.mesh.node_gid[w]);
      EXPECT_TRUE(same_bits(part.mesh.reference[n], whole.mesh.reference[w]));
      EXPECT_EQ(node_star(part.mesh, n).size(), node_star(whole.mesh, w).size());
      const auto mine = d.node_ranks(n), all = wd.node_ranks(w);
      EXPECT_TRUE(std::equal(mine.begin(), mine.end(), all.begin(), all.end())) << "node " << w;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
  if (ranks > 1) {
    EXPECT_LT(d.local_elements().size(), static_cast<size_t>(part.mesh.num_elements()));
  }
}


TEST(Decomposition, FractureRestartOnPartsReadsItsOwnRows) {
  // A checkpoint of a cracked model, written by one rank: each part reads only
  // the rows of its elements' nodes and of its facets' cohesive elements, and
  // continues the run bit for bit.
  const int ranks = world_size();
  const Scene scene = test::scene_from_text(
      "fracture_restart_parts",
      "name: fracture_restart_parts\ntime: {end: 1.0}\nmaterials:\n"
      "  alu: {model: neo_hookean, density: 2750, youngs_modulus: 275.0e9, poisson_ratio: 0.3,\n"
      "        fracture: {strength: 3.0e8, energy: 100.0, beta: 1.0}}\n"
      "bodies:\n  - {name: b, material: alu, mesh: {shape: box, size: [0.024, 0.002, 0.002], element_size: 0.0005},\n"
      "      velocity_gradient: [[2.0e4, 0, 0], [0, 2.0e4, 0], [0, 0, 0]]}\n");
  Model whole = build_model(scene);
  Simulation one(whole, {});
  while (one.ledger().cohesive_elements == 0 && one.steps() < 400) one.step();
  for (int s = 0; s < 20; ++s) one.step();
  ASSERT_GT(one.ledger().cohesive_elements, 0) << "the box did not crack";
  const std::filesystem::path file = run_file("fracture_restart_parts.h5");
  if (world_rank() == 0) {
    SimulationState state;
    one.save_state(state);
    write_checkpoint(file, whole, state);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  Model part = build_model(scene, MPI_COMM_WORLD);
  const SimulationState read = read_checkpoint(file, part);
  ASSERT_TRUE(read.fracture);
  const FractureState& f = *read.fracture;
  EXPECT_EQ(f.whole_nodes, whole.mesh.num_nodes());
  if (ranks > 1) {
    ASSERT_EQ(read.x.size(), f.node_rows.size());
    for (size_t i = 0; i < f.node_rows.size(); ++i) EXPECT_TRUE(same_bits(read.x[i], one.positions()[f.node_rows[i]]));
    // Its own rows only: fewer nodes and cohesive elements than the whole model's.
    EXPECT_LT(f.node_rows.size(), static_cast<size_t>(whole.mesh.num_nodes()));
    EXPECT_LT(f.cohesive_facet_gid.size(), static_cast<size_t>(one.ledger().cohesive_elements));
  }
  RunOptions options;
  options.ranks = ranks;
  Simulation continued(part, options);
  continued.restore_state(read);
  for (int s = 0; s < 20; ++s) {
    one.step();
    continued.step();
  }
  EXPECT_EQ(continued.ledger().cohesive_elements, one.ledger().cohesive_elements);
  EXPECT_EQ(continued.energy_error(), one.energy_error());
  const Decomposition& d = continued.decomposition();
  long checked = 0;
  for (Index n = 0; n < part.mesh.num_nodes(); ++n)
    if (d.owns_node(n)) {
      EXPECT_TRUE(same_bits(continued.positions()[n], one.positions()[part.whole_node(n)])) << "node " << part.whole_node(n);
      ++checked;
    }
  EXPECT_GT(checked, 0);
}

TEST(Decomposition, UpdateAfterInsertionEqualsRebuild) {
  // update_nodes, around the split nodes only, leaves the lists and the halo
  // plan that rebuild_nodes makes over the whole part; three rounds of
  // insertion on the parts of two ghost layers, the later ones splitting copies.
  const Scene scene = test::scene_from_text(
      "fracture_update",
      "name: fracture_update\ntime: {end: 1.0}\nmaterials:\n"
      "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3,\n"
      "          fracture: {strength: 3.0e8, energy: 100.0, beta: 1.0}}\n"
      "bodies:\n  - {name: b, material: steel, mesh: {shape: box, size: [0.02, 0.016, 0.012], element_size: 0.002}}\n");
  Model part = build_model(scene, MPI_COMM_WORLD);
  Decomposition updated(part, MPI_COMM_WORLD), rebuilt(part, MPI_COMM_WORLD);
  FractureStage stage(part, updated);
  const Topology& t = stage.topology();
  auto name_tag = [&](Index n) -> Vec3 {
    return tag(0) + static_cast<double>(part.mesh.node_gid[n]) * Vec3(1.0, 0.5, -3.0);
  };
  auto same = [](std::span<const Index> a, std::span<const Index> b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  };
  long split = 0;
  for (int round : {0, 1, 2}) {
    // Every rank's choice of its facets, the same list everywhere.
    std::vector<GlobalId> mine;
    for (Index f = 0; f < t.num_facets(); ++f)
      if (t.is_interior(f) && t.facet_state[f] == FacetState::intact &&
          (static_cast<std::uint64_t>(t.facet_gid[f]) * 2654435761u + round) % 100 < 15)
        mine.push_back(t.facet_gid[f]);
    std::vector<GlobalId> gids = updated.allgather(std::span<const GlobalId>(mine));
    std::sort(gids.begin(), gids.end());
    gids.erase(std::unique(gids.begin(), gids.end()), gids.end());
    const std::uint64_t revision = part.mesh.revision;
    const Index before = part.mesh.num_nodes();
    const Insertion ins = stage.insert(gids, key_positions(gids, gids, updated));
    split += static_cast<long>(ins.new_nodes.size());
    part.bc_mask.resize(part.mesh.num_nodes(), 0);
    if (part.holds_two_layers()) number_split_nodes(part, before, revision, updated);
    updated.update_nodes(ins.changed_nodes(), stage.side_nodes(), kCohesiveSlots, ins.first_cohesive,
                         [&](Index n, std::vector<Index>& out) { stage.cohesive_around(n, out); });
    rebuilt.rebuild_nodes(stage.side_nodes(), kCohesiveSlots);
    EXPECT_TRUE(same(updated.local_elements(), rebuilt.local_elements())) << "round " << round;
    EXPECT_TRUE(same(updated.held_nodes(), rebuilt.held_nodes())) << "round " << round;
    EXPECT_TRUE(same(updated.touched_nodes(), rebuilt.touched_nodes())) << "round " << round;
    EXPECT_TRUE(same(updated.ghost_only_nodes(), rebuilt.ghost_only_nodes())) << "round " << round;
    EXPECT_TRUE(same(updated.owned_nodes(), rebuilt.owned_nodes())) << "round " << round;
    for (size_t k = 0; k < updated.owned_granules().size(); ++k)
      EXPECT_TRUE(same(updated.home_nodes(k), rebuilt.home_nodes(k))) << "round " << round << " granule " << k;
    for (Index n = 0; n < part.mesh.num_nodes(); ++n) {
      const auto a = updated.node_ranks(n), b = rebuilt.node_ranks(n);
      ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "round " << round << " node " << n;
    }
    EXPECT_EQ(updated.ghost_bytes(), rebuilt.ghost_bytes()) << "round " << round;
    // Both plans deliver the owners' values (named by the nodes' global ids).
    for (const Decomposition* d : {&updated, &rebuilt}) {
      std::vector<Vec3> x(part.mesh.num_nodes(), Vec3::Constant(-7.0));
      for (Index n : d->touched_nodes()) x[n] = name_tag(n);
      d->begin_ghost_update(x);
      d->end_ghost_update(x);
      for (Index n : d->held_nodes())
        ASSERT_TRUE(same_bits(x[n], name_tag(n)))
            << "round " << round << " node " << n << (d == &updated ? " (updated)" : " (rebuilt)");
    }
  }
  EXPECT_GT(split, 0);
}

}  // namespace
}  // namespace shatter
