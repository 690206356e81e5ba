// Simulation: the run's outputs (SCENE.md "Outputs"): history.csv and
// bodies.csv rows, field frames, fragments.csv and summary.json.
#include <algorithm>

#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/field_output.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/global_sum.hpp"
#include "runtime/parallel.hpp"
#include "runtime/report.hpp"
#include "runtime/row_blocks.hpp"
#include "runtime/simulation.hpp"
#include "runtime/timed.hpp"

namespace shatter {

void Simulation::write_outputs(bool fields) {
  if (opt_.out_dir.empty()) return;
  const bool root = dec_->rank() == 0;
  // The fragments' element ids: topology, the same on every rank.
  const Fragments* frags = fracture_ ? &fracture_->fragment_labels() : nullptr;
  if (frags) ledger_.fragments = frags->count();
  const Ledger& l = ledger_;
  if (root) {
    *history_ << step_ << time_ << dt_ << l.kinetic << l.strain << l.cohesive_stored << l.cohesive_dissipated
              << l.contact_dissipated << l.contact_work << l.external_work << l.total() << l.momentum.x() << l.momentum.y()
              << l.momentum.z() << l.angular_momentum.x() << l.angular_momentum.y() << l.angular_momentum.z()
              << l.contacts << l.cohesive_elements << l.fragments << l.contact_capped_steps;
    history_->end_row();
  }

  // Body rows: mass, m x, m v per body, exact sums over the owned nodes.
  const Mesh& mesh = model_.mesh;
  const int nb = static_cast<int>(model_.scene.bodies.size());
  std::vector<ExactSum> sums(static_cast<size_t>(nb) * 7);
  for (Index i : dec_->owned_nodes()) {
    ExactSum* r = sums.data() + static_cast<size_t>(mesh.node_body[i]) * 7;
    const double m = model_.mass[i];
    r[0] += m;
    for (int c = 0; c < 3; ++c) r[1 + c] += m * x_[i][c], r[4 + c] += m * v_[i][c];
  }
  // Only the root writes them.
  if (dec_->distributed()) timed(comm_seconds_, [&] { reduce_to_root(sums, dec_->comm()); });
  for (int b = 0; b < nb && root; ++b) {
    const ExactSum* r = sums.data() + static_cast<size_t>(b) * 7;
    const double mass = r[0].value();
    const Vec3 c = Vec3(r[1].value(), r[2].value(), r[3].value()) / mass,
               v = Vec3(r[4].value(), r[5].value(), r[6].value()) / mass;
    *bodies_ << step_ << time_ << model_.scene.bodies[b].name << mass << c.x() << c.y() << c.z() << v.x() << v.y()
             << v.z();
    bodies_->end_row();
  }

  if (root) history_->flush(), bodies_->flush();
  if (fields && fields_) write_fields(frags ? frags->elem_fragment : std::span<const Index>{});
}

namespace {

/// The shells' mid-surface at positions x and velocities v, the rows this
/// rank writes: each rank packs its owned control vertices (the limit surface
/// there, ShellBody::limit_*, whose stencil reads vertices of a patch it
/// computes) and the triangles whose patches it owns (corners in whole
/// shell-vertex rows, body, resultants); the rows move to contiguous blocks
/// of the whole order (row_blocks.hpp), as the solids' do.
ShellFrame shell_frame(const Model& model, const Decomposition& dec, std::span<const Vec3> x,
                       std::span<const Vec3> v, const ShellForces& forces) {
  constexpr int kVertexWidth = 9, kTriangleWidth = 16;  // X, u, v; corners, body, n (6), m (6)
  constexpr int row[6] = {0, 1, 2, 1, 0, 0}, col[6] = {0, 1, 2, 2, 2, 1};  // Voigt xx yy zz yz xz xy
  const std::vector<ShellResultants> resultants = forces.resultants(x);
  std::vector<Index> vertex_ids, triangle_ids;
  std::vector<double> vertex_rows, triangle_rows;
  Index row0 = 0, triangle0 = 0;
  for (std::size_t b = 0; b < model.shells.size(); ++b) {
    const ShellBody& sb = model.shells[b];
    for (Index p = 0; p < sb.mesh.num_vertices(); ++p) {
      if (!dec.owns_node(sb.first_node + p)) continue;
      Vec3 du = Vec3::Zero(), dv = Vec3::Zero();
      for (Index k = sb.limit_offsets[p]; k < sb.limit_offsets[p + 1]; ++k) {
        const Index i = sb.first_node + sb.limit_vertex[k];
        du += sb.limit_weight[k] * (x[i] - model.mesh.reference[i]);
        dv += sb.limit_weight[k] * v[i];
      }
      vertex_ids.push_back(row0 + p);
      for (const Vec3& w : {sb.limit_reference[p], du, dv}) vertex_rows.insert(vertex_rows.end(), w.data(), w.data() + 3);
    }
    for (Index t = 0; t < sb.mesh.num_triangles(); ++t) {
      if (!forces.owns_triangle(b, t)) continue;
      triangle_ids.push_back(triangle0 + t);
      for (const Index c : sb.mesh.triangles[t]) triangle_rows.push_back(static_cast<double>(row0 + c));
      triangle_rows.push_back(sb.body);
      const ShellResultants& r = resultants[triangle0 + t];
      for (int c = 0; c < 6; ++c) triangle_rows.push_back(r.n(row[c], col[c]));
      for (int c = 0; c < 6; ++c) triangle_rows.push_back(r.m(row[c], col[c]));
    }
    row0 += sb.mesh.num_vertices();
    triangle0 += sb.mesh.num_triangles();
  }
  const MPI_Comm comm = dec.distributed() ? dec.comm() : MPI_COMM_SELF;
  const std::vector<double> vb = to_row_blocks(vertex_ids, vertex_rows, kVertexWidth, row0, comm);
  const std::vector<double> tb = to_row_blocks(triangle_ids, triangle_rows, kTriangleWidth, triangle0, comm);
  ShellFrame out;
  for (std::size_t r = 0; r < vb.size(); r += kVertexWidth) {
    out.reference.emplace_back(vb[r], vb[r + 1], vb[r + 2]);
    out.displacement.emplace_back(vb[r + 3], vb[r + 4], vb[r + 5]);
    out.velocity.emplace_back(vb[r + 6], vb[r + 7], vb[r + 8]);
  }
  for (std::size_t r = 0; r < tb.size(); r += kTriangleWidth) {
    out.triangles.push_back({static_cast<Index>(tb[r]), static_cast<Index>(tb[r + 1]), static_cast<Index>(tb[r + 2])});
    out.body.push_back(static_cast<int>(tb[r + 3]));
    out.membrane_force.insert(out.membrane_force.end(), tb.begin() + r + 4, tb.begin() + r + 10);
    out.bending_moment.insert(out.bending_moment.end(), tb.begin() + r + 10, tb.begin() + r + 16);
  }
  return out;
}

}  // namespace

void Simulation::write_fields(std::span<const Index> elem_fragment) {
  // Each rank packs its owned nodes and elements; the rows move to
  // contiguous blocks in global order (row_blocks.hpp), which each rank
  // writes collectively: the file is the same for any decomposition, and no
  // rank gathers the model.
  const Mesh& mesh = model_.mesh;
  const int k = mesh.nodes_per_element();
  const bool cracks = !elem_fragment.empty();
  const std::span<const Index> nodes = dec_->owned_nodes(), elems = dec_->owned_element_ids();
  // The rows of the whole model (a part's local ids ascend with them).
  std::vector<Index> node_ids(nodes.size()), elem_ids(elems.size());
  for (size_t r = 0; r < nodes.size(); ++r) node_ids[r] = model_.whole_node(nodes[r]);
  for (size_t r = 0; r < elems.size(); ++r) elem_ids[r] = model_.whole_element(elems[r]);
  constexpr int kNodeWidth = 9;  // X, u, v
  std::vector<double> node_rows(nodes.size() * kNodeWidth);
  parallel_for_each(static_cast<Index>(nodes.size()), [&](Index r) {
    const Index i = nodes[r];
    double* o = node_rows.data() + static_cast<size_t>(r) * kNodeWidth;
    const Vec3 u = x_[i] - mesh.reference[i];
    for (int c = 0; c < 3; ++c) o[c] = mesh.reference[i][c], o[3 + c] = u[c], o[6 + c] = v_[i][c];
  });
  // Per element: connectivity, stress (6), von Mises, body, and with fracture fragment and damage.
  const int width = k + 9 + (cracks ? 2 : 0);
  const std::vector<double> damage = cracks ? fracture_->damage() : std::vector<double>{};
  std::vector<double> elem_rows(elems.size() * width);
  parallel_for_each(static_cast<Index>(elems.size()), [&](Index r) {
    const Index e = elems[r];
    double* o = elem_rows.data() + static_cast<size_t>(r) * width;
    for (int a = 0; a < k; ++a) o[a] = model_.whole_node(mesh.element(e)[a]);
    double* s6 = o + k;
    element_cauchy_stress6(model_, x_, e, s6);
    Mat3 sigma;
    sigma << s6[0], s6[5], s6[4], s6[5], s6[1], s6[3], s6[4], s6[3], s6[2];
    o[k + 6] = von_mises(sigma);
    o[k + 7] = mesh.elem_body[e];
    if (cracks) o[k + 8] = elem_fragment[e], o[k + 9] = damage[e];
  });
  const MPI_Comm comm = dec_->distributed() ? dec_->comm() : MPI_COMM_SELF;
  const std::vector<double> nb = to_row_blocks(node_ids, node_rows, kNodeWidth, model_.whole_nodes(), comm);
  const std::vector<double> eb = to_row_blocks(elem_ids, elem_rows, width, model_.whole_elements(), comm);

  // This rank's block as a mesh (connectivity in global node rows) and frame.
  const size_t bn = nb.size() / kNodeWidth, be = eb.size() / width;
  Mesh block;
  block.order = mesh.order;
  block.revision = mesh.revision;
  block.reference.resize(bn);
  std::vector<Vec3> u(bn), v(bn);
  for (size_t r = 0; r < bn; ++r) {
    const double* o = nb.data() + r * kNodeWidth;
    block.reference[r] = Vec3(o[0], o[1], o[2]);
    u[r] = Vec3(o[3], o[4], o[5]);
    v[r] = Vec3(o[6], o[7], o[8]);
  }
  block.conn.resize(be * k);
  block.elem_gid.resize(be);
  std::vector<double> stress(6 * be), vm(be), block_damage(cracks ? be : 0);
  std::vector<int> body(be), fragment(cracks ? be : 0);
  for (size_t r = 0; r < be; ++r) {
    const double* o = eb.data() + r * width;
    for (int a = 0; a < k; ++a) block.conn[r * k + a] = static_cast<Index>(o[a]);
    std::copy_n(o + k, 6, stress.begin() + 6 * r);
    vm[r] = o[k + 6];
    body[r] = static_cast<int>(o[k + 7]);
    if (cracks) fragment[r] = static_cast<int>(o[k + 8]), block_damage[r] = o[k + 9];
  }
  FieldFrame f;
  f.step = static_cast<int>(step_);
  f.time = time_;
  f.displacement = u;
  f.velocity = v;
  f.stress = stress;
  f.von_mises = vm;
  f.body = body;
  f.fragment = fragment;
  f.damage = block_damage;
  // A shell vertex's limit velocity reads its patches' vertices: the
  // ghost-only ones get their owners' velocities (the step sends positions only).
  std::vector<Vec3> shell_v;
  if (shells_ && dec_->distributed()) {
    shell_v = v_;
    dec_->begin_ghost_update(shell_v);
    dec_->end_ghost_update(shell_v);
  }
  const ShellFrame shells =
      shells_ ? shell_frame(model_, *dec_, x_, shell_v.empty() ? v_ : shell_v, *shells_) : ShellFrame{};
  if (shells_) f.shells = &shells;
  fields_->write(block, f);
}

CrackArea Simulation::write_fragments() {
  // Each rank sums its owned nodes and elements, exactly; rank 0 adds the ranks' sums.
  Fragments frags = fracture_->fragment_labels();  // a copy: the statistics are added to it
  std::vector<ExactSum> sums = fragment_sums(model_.mesh, frags, dec_->owned_nodes(), dec_->owned_element_ids(), x_,
                                             v_, model_.mass);
  if (dec_->distributed()) reduce_to_root(sums, dec_->comm());
  // The crack areas of each rank's owned cohesive elements, summed exactly.
  const CrackArea owned = fracture_->crack_area(frags);
  ExactSum areas[] = {owned.debonded, owned.between_fragments, owned.debonded_dissipated};
  dec_->sum(areas);
  if (dec_->rank() != 0) return {};
  set_fragment_stats(frags, sums);
  CsvWriter out(opt_.out_dir / "fragments.csv",
                {"id", "mass", "volume", "cx", "cy", "cz", "vx", "vy", "vz", "elements"});
  for (Index k = 0; k < frags.count(); ++k) {
    const FragmentStats& s = frags.stats[k];
    out << static_cast<long>(k) << s.mass << s.volume << s.centre.x() << s.centre.y() << s.centre.z()
        << s.velocity.x() << s.velocity.y() << s.velocity.z() << static_cast<long>(s.elements);
    out.end_row();
  }
  out.flush();
  return {areas[0], areas[1], areas[2]};
}

long Simulation::loop_bytes() const {
  auto b = [](const auto& v) { return static_cast<long>(v.capacity() * sizeof(v[0])); };
  return static_cast<long>(model_bytes(model_)) + b(x_) + b(v_) + b(a_) + b(f_int_) + b(f_ext_) + b(inv_mass_) +
         b(bc_nodes_) + b(reaction_) + b(x_prev_) + b(stress6_);
}

void Simulation::write_summary(double wall, const DecompositionStats& stats, const ContactBalance& contact_balance,
                               const FractureSummary& fracture, const std::pair<std::vector<long>, long>& memory,
                               const std::array<long, 3>& shell) {
  const Ledger& l = ledger_;
  JsonObject j;
  j.add("name", model_.scene.name);
  j.add("scene", model_.scene.file);
  j.add("ranks", dec_->size());
  j.add("threads", opt_.threads);
  j.add("deterministic", std::string(opt_.deterministic ? "true" : "false"));
  j.add("steps", step_);
  j.add("end_time", time_);
  j.add("wall_time", wall);
  j.add("time_per_step", step_ > 0 ? wall / step_ : 0.0);
  j.add("element_loop_time", element_seconds_);
  j.add("mesh_time", model_.mesh_seconds);
  j.add("checkpoint_time", checkpoint_seconds_);
  // element-steps per second per core spent in the element loop (the elements computed: not rigid bodies')
  j.add("element_updates_per_second",
        element_seconds_ > 0 ? double(elements_.computed_elements() + (shells_ ? shells_->elements() : 0)) * (step_ + 1) / (element_seconds_ * opt_.threads)
                             : 0.0);
  j.add("peak_memory_bytes", peak_memory_bytes());
  j.add("peak_memory_bytes_per_rank", memory.first);
  j.add("model_bytes_per_rank_max", memory.second);
  // Decomposition (docs/parallel.md): balance and bytes per step.
  j.add("owned_elements_min", stats.owned_min);
  j.add("owned_elements_max", stats.owned_max);
  j.add("local_elements_max", stats.local_max);
  j.add("ghost_bytes_per_step_max", stats.ghost_bytes_max);
  j.add("ghost_messages_per_step_max", stats.ghost_messages_max);
  if (shells_) {
    // Shell patches (docs/parallel.md "Shells on ranks"): the whole count, owned and computed per rank.
    long triangles = 0;
    for (const ShellBody& s : model_.shells) triangles += s.mesh.num_triangles();
    j.add("shell_elements", triangles);
    j.add("shell_owned_elements_min", shell[0]);
    j.add("shell_owned_elements_max", shell[1]);
    j.add("shell_local_elements_max", shell[2]);
  }
  // No contact surface state goes to every rank any more (the patches, docs/parallel.md).
  j.add("shared_surface_bytes_per_step", 0L);
  // The ledger's exact sums (update_ledger: 7 node terms, the strain energy, the step's work)
  // and the stop signal, one message.
  j.add("reduction_bytes_per_step", static_cast<long>(dec_->distributed() ? Decomposition::sum_bytes(kLedgerSums, kLedgerMaxima) : 0));
  // The contact stage's exchanges included (contact_exchange_time).
  j.add("communication_time", comm_seconds_ + (contact_ ? contact_->profile().exchange_seconds : 0.0));
  j.add("nodes", static_cast<long>(model_.whole_nodes()));
  j.add("elements", static_cast<long>(model_.whole_elements()));
  j.add("element_order", model_.mesh.order);
  j.add("bodies", static_cast<long>(model_.scene.bodies.size()));
  j.add("kinetic", l.kinetic);
  j.add("strain", l.strain);
  j.add("cohesive_stored", l.cohesive_stored);
  j.add("cohesive_dissipated", l.cohesive_dissipated);
  j.add("contact_dissipated", l.contact_dissipated);
  j.add("contact_work", l.contact_work);
  j.add("external_work", l.external_work);
  j.add("total", l.total());
  j.add("initial_total", total0_);
  j.add("energy_error", energy_error());
  j.add("contacts", l.contacts);
  j.add("cohesive_elements", l.cohesive_elements);
  j.add("fragments", l.fragments);
  j.add("contact_capped_steps", l.contact_capped_steps);
  if (fracture_) {
    j.add("fracture_check_time", fracture_->check_seconds());
    j.add("fracture_insert_time", insert_seconds_);
    j.add("fracture_check_cpu_time_max", fracture.check_cpu_max);
    j.add("fracture_insert_cpu_time_max", fracture.insert_cpu_max);
    // Cohesive elements between elements of different ranks: cracks across subdomains.
    j.add("cohesive_elements_across_ranks", fracture.across_ranks);
    j.add("cohesive_elements_per_rank_min", fracture.owned_min);
    j.add("cohesive_elements_per_rank_max", fracture.owned_max);
    j.add("crack_area_debonded", fracture.crack.debonded.value());
    j.add("crack_area_between_fragments", fracture.crack.between_fragments.value());
    j.add("cohesive_dissipated_debonded", fracture.crack.debonded_dissipated.value());
  }
  if (contact_) {
    j.add("contact_search_time", contact_->search_seconds());
    j.add("contact_searches", contact_->searches());
    j.add("contact_dcr_time", contact_->dcr_seconds());
    j.add("contact_surface_triangles", contact_balance.triangles);
    // The split of the two times above and the work per step (docs/scenes.md).
    const ContactProfile& cp = contact_->profile();
    const double steps = std::max(1L, cp.steps);
    j.add("contact_verlet_time", cp.verlet_seconds);
    j.add("contact_sweep_time", cp.sweep_seconds);
    j.add("contact_candidates_per_step", contact_balance.candidates_sum / steps);
    j.add("contact_pairs_per_step", contact_balance.pairs_sum / steps);
    j.add("contact_detections_per_step", cp.detections / steps);
    j.add("contact_sweeps_per_step", cp.sweeps / steps);
    if (dec_->distributed()) {
      j.add("contact_pairs_per_step_rank_min", contact_balance.pairs_min / steps);
      j.add("contact_pairs_per_step_rank_max", contact_balance.pairs_max / steps);
      j.add("contact_exchange_time", cp.exchange_seconds);
      j.add("contact_exchange_bytes_per_step", cp.exchange_bytes / steps);
      j.add("contact_state_bytes_per_step_max", contact_balance.state_bytes_max / steps);
      j.add("contact_found_bytes_per_step_max", contact_balance.found_bytes_max / steps);
      j.add("contact_states_passed", contact_balance.states_posted_sum);
      j.add("contact_search_cpu_time_max", contact_balance.search_cpu_max);
      j.add("contact_dcr_cpu_time_max", contact_balance.sweep_cpu_max);
      j.add("contact_repartitions", cp.repartitions);
      j.add("contact_whole_surface_bytes_max", contact_balance.whole_surface_bytes_max);
      j.add("contact_patch_vertices_max", contact_balance.known_vertices_max);
    }
  }
  j.write(opt_.out_dir / "summary.json");
}

}  // namespace shatter
