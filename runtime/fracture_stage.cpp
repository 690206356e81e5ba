#include "runtime/fracture_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "fracture/facet_criterion.hpp"
#include "fracture/strength_scatter.hpp"
#include "kernels/error.hpp"
#include "kernels/tet4.hpp"

namespace shatter {

FractureStage::FractureStage(Model& model) : model_(model), topology_(build_topology(model.mesh)) {
  const Mesh& mesh = model.mesh;
  const size_t nm = model.scene.materials.size();
  std::vector<double> h_min(nm, HUGE_VAL);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* c = mesh.element(e);
    const auto& X = mesh.reference;
    h_min[mesh.elem_material[e]] =
        std::min(h_min[mesh.elem_material[e]], tet_min_altitude(X[c[0]], X[c[1]], X[c[2]], X[c[3]]));
  }
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
}

std::vector<std::string> FractureStage::cohesive_zone_warnings() const {
  const Mesh& mesh = model_.mesh;
  const size_t nm = model_.scene.materials.size();
  std::vector<double> edge_sum(nm, 0.0);
  std::vector<Index> count(nm, 0);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* c = mesh.element(e);
    double longest = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        longest = std::max(longest, (mesh.reference[c[a]] - mesh.reference[c[b]]).norm());
    edge_sum[mesh.elem_material[e]] += longest;
    ++count[mesh.elem_material[e]];
  }
  std::vector<std::string> out;
  for (size_t m = 0; m < nm; ++m) {
    const MaterialSpec& ms = model_.scene.materials[m];
    if (!ms.fracture || count[m] == 0) continue;
    const double h = edge_sum[m] / count[m];
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

CohesiveEnergy FractureStage::add_forces(std::span<const Vec3> x, std::span<Vec3> f_int) {
  if (cohesive_.size() == 0) return {};
  return cohesive_forces(model_.mesh, topology_, cohesive_, laws(), x, f_int);
}

std::vector<Index> FractureStage::check(std::span<const Vec3> x, std::span<const double> stress6,
                                        std::span<const Index> local, std::span<const Index> owned) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Index> critical = critical_facets(model_.mesh, topology_, x, stress6, 6, laws(), local, owned);
  check_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return critical;
}

Insertion FractureStage::insert(std::span<const Index> facets) {
  if (facets.empty()) return {};
  return insert_cohesive_elements(model_.mesh, topology_, cohesive_, facets);
}

std::vector<Index> FractureStage::cohesive_nodes() const {
  const int k = model_.mesh.order == 1 ? 3 : 6;
  std::vector<Index> nodes;
  nodes.reserve(static_cast<size_t>(cohesive_.size()) * 2 * k);
  for (Index c = 0; c < cohesive_.size(); ++c)
    for (int s = 0; s < 2; ++s)
      for (int j = 0; j < k; ++j) nodes.push_back(cohesive_.side_nodes[(2 * static_cast<size_t>(c) + s) * 6 + j]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

double FractureStage::stable_dt(double element_dt, std::span<const double> mass) {
  if (cohesive_.size() == 0) return element_dt;
  const std::array<Index, 3> key = {cohesive_.size(), model_.mesh.num_nodes(), released_};
  if (key != bound_key_) {
    eigenvalue_bound_ = cohesive_eigenvalue_bound(model_.mesh, topology_, cohesive_, laws(), mass);
    bound_key_ = key;
  }
  const double omega_e = 2.0 / element_dt;
  return 2.0 / std::sqrt(omega_e * omega_e + eigenvalue_bound_);
}

Index FractureStage::release(std::span<const Vec3> x) {
  if (cohesive_.size() == 0) return 0;
  const Index freed = release_debonded(model_.mesh, topology_, cohesive_, laws(), x);
  released_ += freed;  // freed facets exert no force: the eigenvalue bound's key changes
  if (freed > 0) ++facet_revision_;
  return freed;
}

const Fragments& FractureStage::fragment_labels() const {
  if (labels_revision_ != facet_revision_) {
    labels_ = label_fragments(model_.mesh, topology_);
    labels_revision_ = facet_revision_;
  }
  return labels_;
}

void FractureStage::save(FractureState& s) const {
  const Mesh& mesh = model_.mesh;
  if (s.mesh_revision != mesh.revision) {
    s.mesh_revision = mesh.revision;
    s.reference = mesh.reference;
    s.node_gid = mesh.node_gid;
    s.node_body = mesh.node_body;
    s.conn = mesh.conn;
    s.mass = model_.mass;
    s.bc_mask = model_.bc_mask;
    s.bc_velocity = model_.bc_velocity;
    s.bc_condition = model_.bc_condition;
    s.initial_velocity = model_.initial_velocity;
  }
  s.facet_state = topology_.facet_state;
  s.cohesive = cohesive_;
}

void FractureStage::restore(const FractureState& s) {
  Mesh& mesh = model_.mesh;
  const size_t n = s.reference.size(), ne = mesh.num_elements(), k = mesh.nodes_per_element();
  SHATTER_REQUIRE(n >= static_cast<size_t>(mesh.num_nodes()) && s.node_gid.size() == n && s.node_body.size() == n &&
                      s.mass.size() == n && s.bc_mask.size() == n && s.bc_velocity.size() == n && s.bc_condition.size() == n &&
                      s.initial_velocity.size() == n && s.conn.size() == ne * k,
                  "fracture state: node arrays of " << n << " nodes and " << s.conn.size() / k
                                                    << " elements do not fit the model (" << mesh.num_nodes()
                                                    << " nodes before fracture, " << ne << " elements)");
  SHATTER_REQUIRE(s.facet_state.size() == static_cast<size_t>(topology_.num_facets()),
                  "fracture state: " << s.facet_state.size() << " facets, the model has "
                                     << topology_.num_facets());
  for (FacetState f : s.facet_state)
    SHATTER_REQUIRE(f == FacetState::intact || f == FacetState::cohesive || f == FacetState::free,
                    "fracture state: facet state " << int(f) << " is not one of intact, cohesive, free");
  const CohesiveElements& c = s.cohesive;
  const size_t nc = c.facet.size();
  SHATTER_REQUIRE(c.side_local.size() == nc * kCohesiveSlots && c.side_nodes.size() == nc * kCohesiveSlots && c.area.size() == nc &&
                      c.normal.size() == nc && c.delta_max.size() == nc * kCohesivePoints,
                  "fracture state: the cohesive element arrays disagree in size");
  for (Index a : s.conn) SHATTER_REQUIRE(a >= 0 && static_cast<size_t>(a) < n, "fracture state: node " << a << " in conn is out of range");
  for (Index f : c.facet)
    SHATTER_REQUIRE(f >= 0 && f < topology_.num_facets() && s.facet_state[f] != FacetState::intact,
                    "fracture state: cohesive facet " << f << " is out of range or intact");
  for (Index a : c.side_nodes)
    SHATTER_REQUIRE(a >= -1 && (a < 0 || static_cast<size_t>(a) < n), "fracture state: side node " << a << " is out of range");
  for (std::int8_t a : c.side_local)
    SHATTER_REQUIRE(a >= -1 && a < static_cast<int>(k), "fracture state: local node " << int(a) << " is out of range");
  for (int b : s.node_body)
    SHATTER_REQUIRE(b >= 0 && static_cast<size_t>(b) < model_.scene.bodies.size(), "fracture state: body " << b << " is out of range");

  mesh.reference = s.reference;
  mesh.node_gid = s.node_gid;
  mesh.node_body = s.node_body;
  mesh.conn = s.conn;
  mesh.build_node_elements();
  mesh.revision = s.mesh_revision;
  model_.mass = s.mass;
  model_.bc_mask = s.bc_mask;
  model_.bc_velocity = s.bc_velocity;
  model_.bc_condition = s.bc_condition;
  model_.initial_velocity = s.initial_velocity;
  topology_.facet_state = s.facet_state;
  ++facet_revision_;
  cohesive_ = s.cohesive;
  bound_key_ = {-1, -1, -1};  // the cohesive elements changed: compute the bound afresh
}

}  // namespace shatter
