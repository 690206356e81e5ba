#include "runtime/fracture_stage.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "fracture/facet_criterion.hpp"
#include "fracture/strength_scatter.hpp"
#include "kernels/error.hpp"
#include "kernels/tet4.hpp"
#include "runtime/sort_unique.hpp"
#include "runtime/timed.hpp"

namespace shatter {

namespace {

/// The largest node global id of the whole model (the split copies' names start past it).
GlobalId largest_node_gid(const Mesh& mesh, const Decomposition& dec) {
  const long mine = mesh.node_gid.empty() ? 0 : *std::max_element(mesh.node_gid.begin(), mesh.node_gid.end());
  return dec.max(mine);
}

}  // namespace

FractureStage::FractureStage(Model& model, const Decomposition& dec)
    : model_(model), dec_(dec), topology_(build_topology(model.mesh, largest_node_gid(model.mesh, dec))) {
  stamp_facets();
  const Mesh& mesh = model.mesh;
  const size_t nm = model.scene.materials.size();
  // The whole model's smallest altitude per material, from the owned elements.
  std::vector<double> h_min(nm, HUGE_VAL);
  for (Index e : dec.owned_element_ids()) {
    const Index* c = mesh.element(e);
    const auto& X = mesh.reference;
    h_min[mesh.elem_material[e]] =
        std::min(h_min[mesh.elem_material[e]], tet_min_altitude(X[c[0]], X[c[1]], X[c[2]], X[c[3]]));
  }
  dec.min(h_min);
  std::vector<std::optional<StrengthScatter>> scatter(nm);
  for (size_t m = 0; m < nm; ++m) {
    const MaterialSpec& ms = model.scene.materials[m];
    if (ms.fracture) {
      laws_.emplace_back(make_cohesive_law(ms.fracture->strength, ms.fracture->energy, ms.fracture->beta,
                                           ms.young / h_min[m]));
      scatter[m] = ms.fracture->scatter;
    } else {
      laws_.emplace_back(std::nullopt);
    }
  }
  if (std::any_of(scatter.begin(), scatter.end(), [](const auto& s) { return s.has_value(); })) {
    facet_strength_ = facet_strengths(mesh, topology_, laws_, scatter);
    weakest_facet_ = *std::min_element(facet_strength_.begin(), facet_strength_.end());
  }
  // The interior facets by global id, for the lists every rank applies.
  for (Index f = 0; f < topology_.num_facets(); ++f)
    if (topology_.is_interior(f)) by_gid_.push_back(f);
  std::sort(by_gid_.begin(), by_gid_.end(),
            [&](Index a, Index b) { return topology_.facet_gid[a] < topology_.facet_gid[b]; });
  for (const Index f : by_gid_) sorted_gids_.push_back(topology_.facet_gid[f]);
}

std::vector<GlobalId> FractureStage::gids(std::span<const Index> facets) const {
  std::vector<GlobalId> out;
  out.reserve(facets.size());
  for (Index f : facets) out.push_back(topology_.facet_gid[f]);
  return out;
}

std::vector<Index> FractureStage::facets(std::span<const GlobalId> gids) const {
  std::vector<Index> out;
  for (GlobalId g : gids) {
    const auto it = std::lower_bound(sorted_gids_.begin(), sorted_gids_.end(), g);
    if (it != sorted_gids_.end() && *it == g) out.push_back(by_gid_[it - sorted_gids_.begin()]);
  }
  return out;
}

std::vector<std::string> FractureStage::cohesive_zone_warnings() const {
  // The mean longest edge per material over the whole model, from the owned elements.
  const Mesh& mesh = model_.mesh;
  const size_t nm = model_.scene.materials.size();
  std::vector<ExactSum> edge_sum(nm);
  std::vector<long> count(nm, 0);
  for (Index e : dec_.owned_element_ids()) {
    const Index* c = mesh.element(e);
    double longest = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        longest = std::max(longest, (mesh.reference[c[a]] - mesh.reference[c[b]]).norm());
    edge_sum[mesh.elem_material[e]] += longest;
    ++count[mesh.elem_material[e]];
  }
  dec_.sum(edge_sum);
  count = dec_.sum(count);
  std::vector<std::string> out;
  for (size_t m = 0; m < nm; ++m) {
    const MaterialSpec& ms = model_.scene.materials[m];
    if (!ms.fracture || count[m] == 0) continue;
    const double h = edge_sum[m].value() / count[m];
    const double l_cz = ms.young * ms.fracture->energy / (ms.fracture->strength * ms.fracture->strength);
    if (l_cz >= kCohesiveZoneElements * h) continue;
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "warning: %s: materials.%s.fracture: the cohesive zone E Gc / sigma_c^2 = %.3e m is shorter "
                  "than %d elements (mean longest edge h = %.3e m): the mesh does not resolve it, cracks "
                  "snap through an element at a time and crack paths and fragment sizes depend on the mesh",
                  model_.scene.file.c_str(), ms.name.c_str(), l_cz, kCohesiveZoneElements, h);
    out.emplace_back(buf);
  }
  return out;
}

void FractureStage::share() {
  if (!labeler_) labeler_ = std::make_unique<FragmentLabels>(model_, topology_, dec_);
  computed_.clear();
  owned_.clear();
  if (!dec_.distributed()) return;
  for (Index c = 0; c < cohesive_.size(); ++c) share_one(c);
  // (A rank owning a cohesive element touches its first element's nodes: it computes it.)
}

void FractureStage::share_one(Index c) {
  const Index* nodes = cohesive_.side_nodes.data() + static_cast<size_t>(c) * kCohesiveSlots;
  if (std::none_of(nodes, nodes + kCohesiveSlots, [&](Index n) { return n >= 0 && dec_.touches(n, dec_.rank()); }))
    return;
  computed_.push_back(c);
  owned_.push_back(dec_.owns_element(topology_.facet_elem[cohesive_.facet[c]][0]) ? 1 : 0);
}

void FractureStage::share(const Insertion& ins) {
  if (!dec_.distributed()) return;
  std::vector<Index> near;
  for (const Index n : ins.changed_nodes()) cohesive_around(n, near);
  sort_unique(near);
  std::vector<char> is_near(cohesive_.size(), 0);
  for (const Index c : near) is_near[c] = 1;
  // The others kept, in order, with the near ones (older than the new ones) merged in.
  std::vector<Index> computed = std::move(computed_);
  std::vector<std::uint8_t> owned = std::move(owned_);
  computed_.clear();
  owned_.clear();
  auto c = near.begin();
  for (size_t i = 0; i < computed.size(); ++i) {
    if (is_near[computed[i]]) continue;
    for (; c != near.end() && *c < computed[i]; ++c) share_one(*c);
    computed_.push_back(computed[i]);
    owned_.push_back(owned[i]);
  }
  for (; c != near.end(); ++c)
    if (*c < ins.first_cohesive) share_one(*c);
  for (Index fresh = ins.first_cohesive; fresh < cohesive_.size(); ++fresh) share_one(fresh);
}

CohesiveEnergy FractureStage::add_forces(std::span<const Vec3> x, std::span<Vec3> f_int) {
  if (cohesive_.size() == 0) return {};
  return cohesive_forces(model_.mesh, topology_, cohesive_, laws(), x, f_int, mine());
}

std::vector<Index> FractureStage::check(std::span<const Vec3> x, std::span<const double> stress6,
                                        std::span<const Index> local, std::span<const Index> owned) {
  return timed(check_seconds_, check_cpu_seconds_,
               [&] { return critical_facets(model_.mesh, topology_, x, stress6, 6, laws(), local, owned); });
}

Insertion FractureStage::insert(std::span<const GlobalId> gids, const KeyPositions& whole) {
  SHATTER_REQUIRE(whole.position.size() == gids.size(), "FractureStage::insert: " << whole.position.size()
                                                            << " positions for " << gids.size() << " facets");
  SHATTER_REQUIRE(std::is_sorted(gids.begin(), gids.end()), "FractureStage::insert: facet ids not ascending");
  const std::vector<Index> held = facets(gids);
  Insertion ins;
  ins.first_cohesive = cohesive_.size();
  if (!held.empty()) {
    ins = insert_cohesive_elements(model_.mesh, topology_, cohesive_, held);
    stamp_facets();
  }
  // The whole model inserts its critical facets in the order of their ids.
  for (Index c = ins.first_cohesive; c < cohesive_.size(); ++c) {
    const auto at = std::lower_bound(gids.begin(), gids.end(), topology_.facet_gid[cohesive_.facet[c]]) - gids.begin();
    SHATTER_REQUIRE(whole.position[at] >= 0, "FractureStage::insert: facet " << gids[at] << " was found by no rank");
    cohesive_whole_.push_back(whole_cohesive_ + whole.position[at]);
  }
  whole_cohesive_ += whole.total;
  index_cohesive(ins.first_cohesive);
  return ins;
}

void FractureStage::index_cohesive(Index first) {
  facet_cohesive_.resize(topology_.num_facets(), -1);
  for (Index c = first; c < cohesive_.size(); ++c) facet_cohesive_[cohesive_.facet[c]] = c;
}

void FractureStage::cohesive_around(Index n, std::vector<Index>& out) const {
  const Mesh& mesh = model_.mesh;
  const int k = mesh.order == 1 ? 3 : 6;
  for (const Index e : node_star(mesh, n))
    for (int i = 0; i < 4; ++i) {
      const Index c = facet_cohesive_[topology_.elem_facet[static_cast<size_t>(e) * 4 + i]];
      if (c < 0) continue;
      const std::array<Index, 6> face = face_nodes(mesh, e, i);
      if (std::find(face.begin(), face.begin() + k, n) != face.begin() + k) out.push_back(c);
    }
}

double FractureStage::eigenvalue_bound(std::span<const double> mass) {
  if (cohesive_.size() == 0) return 0;
  const std::array<Index, 3> key = {cohesive_.size(), model_.mesh.num_nodes(), released_};
  if (key != bound_key_) {
    eigenvalue_bound_ = cohesive_eigenvalue_bound(model_.mesh, topology_, cohesive_, laws(), mass, mine());
    bound_key_ = key;
  }
  return eigenvalue_bound_;
}

std::vector<Index> FractureStage::debonded() const {
  if (cohesive_.size() == 0) return {};
  return debonded_facets(topology_, cohesive_, mine());
}

std::vector<std::pair<Index, int>> FractureStage::bonded_faces() const {
  std::vector<std::pair<Index, int>> faces;
  for (const Index f : cohesive_.facet)
    if (topology_.facet_state[f] == FacetState::cohesive)
      for (int side = 0; side < 2; ++side) faces.emplace_back(topology_.facet_elem[f][side], topology_.facet_face[f][side]);
  std::sort(faces.begin(), faces.end());
  return faces;
}

std::vector<std::array<Index, 2>> FractureStage::bonded_twins() const {
  std::vector<std::array<Index, 2>> twins;
  for (Index c = 0; c < cohesive_.size(); ++c) {
    if (topology_.facet_state[cohesive_.facet[c]] != FacetState::cohesive) continue;
    // kCohesiveSlots per element: side 0's facet nodes, then side 1's, matched slot by slot.
    constexpr int kSide = kCohesiveSlots / 2;
    const Index* side = cohesive_.side_nodes.data() + static_cast<size_t>(c) * kCohesiveSlots;
    for (int j = 0; j < kSide; ++j)
      if (side[j] >= 0 && side[j] != side[kSide + j]) twins.push_back({side[j], side[kSide + j]});
  }
  return twins;
}

void FractureStage::release(std::span<const GlobalId> gids, Index freed) {
  const std::vector<Index> held = facets(gids);
  for (Index f : held) topology_.facet_state[f] = FacetState::free;
  if (!held.empty()) stamp_facets();
  released_ += static_cast<Index>(held.size());  // freed facets exert no force: the eigenvalue bound's key changes
  // (The fragments change on every rank, whichever facets it holds.)
  if (freed > 0) ++facet_revision_;
}

long FractureStage::across_ranks() const {
  long mine = 0;
  for (Index f : cohesive_.facet) {
    const auto [e0, e1] = topology_.facet_elem[f];
    mine += dec_.owns_element(e0) && dec_.element_rank(e1) != dec_.rank();
  }
  return dec_.sum(std::vector<long>{mine})[0];
}

const Fragments& FractureStage::fragment_labels() const {
  if (labels_revision_ != facet_revision_) {
    labels_ = labeler_->label(topology_);
    labels_revision_ = facet_revision_;
  }
  return labels_;
}

void FractureStage::stamp_facets() {
  static std::atomic<std::uint64_t> last{0};
  facet_stamp_ = ++last;
}

void FractureStage::save(FractureState& s) const {
  const Mesh& mesh = model_.mesh;
  // (On a part the outer ghost layer may split without a new revision: the sizes tell.)
  if (s.mesh_revision != mesh.revision || s.reference.size() != static_cast<size_t>(mesh.num_nodes())) {
    s.mesh_revision = mesh.revision;
    copy_node_arrays(s, model_);
    s.conn = mesh.conn;
  }
  if (s.facet_stamp != facet_stamp_) {
    s.facet_stamp = facet_stamp_;
    s.facet_gid.clear();
    s.facet_state.clear();
    for (Index f : by_gid_)
      if (topology_.facet_state[f] != FacetState::intact) {
        s.facet_gid.push_back(topology_.facet_gid[f]);
        s.facet_state.push_back(topology_.facet_state[f]);
      }
    s.cohesive_facet_gid = gids(cohesive_.facet);
  }
  s.cohesive = cohesive_;
  s.cohesive.facet.clear();
  s.whole_nodes = model_.whole_nodes();
  s.whole_cohesive = whole_cohesive_;
  s.cohesive_whole = cohesive_whole_;
}

void FractureStage::restore(const FractureState& whole) {
  const FractureState local = model_.holds_two_layers() ? part_of(whole) : FractureState{};
  const FractureState& s = model_.holds_two_layers() ? local : whole;
  Mesh& mesh = model_.mesh;
  const size_t n = s.reference.size(), ne = mesh.num_elements(), k = mesh.nodes_per_element();
  SHATTER_REQUIRE(n >= static_cast<size_t>(mesh.num_nodes()) && s.node_gid.size() == n && s.node_body.size() == n &&
                      s.mass.size() == n && s.bc_mask.size() == n && s.bc_velocity.size() == n && s.bc_condition.size() == n &&
                      s.initial_velocity.size() == n && s.conn.size() == ne * k,
                  "fracture state: node arrays of " << n << " nodes and " << s.conn.size() / k
                                                    << " elements do not fit the model (" << mesh.num_nodes()
                                                    << " nodes before fracture, " << ne << " elements)");
  // The named facets: interior facets of this topology, ascending, each once.
  const std::vector<Index> open = facets(s.facet_gid);
  SHATTER_REQUIRE(s.facet_state.size() == s.facet_gid.size() && open.size() == s.facet_gid.size() &&
                      std::is_sorted(s.facet_gid.begin(), s.facet_gid.end()) &&
                      std::adjacent_find(s.facet_gid.begin(), s.facet_gid.end()) == s.facet_gid.end(),
                  "fracture state: " << s.facet_gid.size() << " facet ids, " << open.size()
                                     << " of them interior facets of the model, ascending and distinct, and "
                                     << s.facet_state.size() << " states");
  for (FacetState f : s.facet_state)
    SHATTER_REQUIRE(f == FacetState::cohesive || f == FacetState::free,
                    "fracture state: facet state " << int(f) << " is not one of cohesive, free");
  const CohesiveElements& c = s.cohesive;
  const size_t nc = s.cohesive_facet_gid.size();
  const std::vector<Index> cohesive_facets = facets(s.cohesive_facet_gid);
  SHATTER_REQUIRE(cohesive_facets.size() == nc, "fracture state: a cohesive facet id is no interior facet of the model");
  SHATTER_REQUIRE(c.side_local.size() == nc * kCohesiveSlots && c.side_nodes.size() == nc * kCohesiveSlots && c.area.size() == nc &&
                      c.normal.size() == nc && c.delta_max.size() == nc * kCohesivePoints,
                  "fracture state: the cohesive element arrays disagree in size");
  for (Index a : s.conn) SHATTER_REQUIRE(a >= 0 && static_cast<size_t>(a) < n, "fracture state: node " << a << " in conn is out of range");
  for (GlobalId g : s.cohesive_facet_gid)
    SHATTER_REQUIRE(std::binary_search(s.facet_gid.begin(), s.facet_gid.end(), g),
                    "fracture state: cohesive facet " << g << " is intact");
  for (Index a : c.side_nodes)
    SHATTER_REQUIRE(a >= -1 && (a < 0 || static_cast<size_t>(a) < n), "fracture state: side node " << a << " is out of range");
  for (std::int8_t a : c.side_local)
    SHATTER_REQUIRE(a >= -1 && a < static_cast<int>(k), "fracture state: local node " << int(a) << " is out of range");
  for (int b : s.node_body)
    SHATTER_REQUIRE(b >= 0 && static_cast<size_t>(b) < model_.scene.bodies.size(), "fracture state: body " << b << " is out of range");

  copy_node_arrays(model_, s);
  mesh.conn = s.conn;
  mesh.build_node_elements();
  mesh.revision = s.mesh_revision;
  for (Index f : by_gid_) topology_.facet_state[f] = FacetState::intact;
  for (size_t i = 0; i < open.size(); ++i) topology_.facet_state[open[i]] = s.facet_state[i];
  ++facet_revision_;
  stamp_facets();
  cohesive_ = s.cohesive;
  cohesive_.facet = cohesive_facets;
  facet_cohesive_.assign(topology_.num_facets(), -1);
  index_cohesive(0);
  if (model_.holds_two_layers()) {
    whole_cohesive_ = s.whole_cohesive;
    cohesive_whole_ = s.cohesive_whole;
  } else {  // the whole model's state: its own numbering
    whole_cohesive_ = cohesive_.size();
    cohesive_whole_.resize(cohesive_.size());
    std::iota(cohesive_whole_.begin(), cohesive_whole_.end(), 0);
  }
  bound_key_ = {-1, -1, -1};  // the cohesive elements changed: compute the bound afresh
}

}  // namespace shatter
