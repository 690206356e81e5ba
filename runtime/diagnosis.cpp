#include "runtime/diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace shatter {

std::string sweep_cap_diagnosis(const Model& model, const std::optional<UnresolvedPair>& pair, long step,
                                double time) {
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: DCR sweeps reached the cap (contact.max_sweeps = "
     << model.scene.contact->max_sweeps << ") with penetrations left (contact.on_sweep_cap: fail)";
  if (pair) {
    Vec3 centre = Vec3::Zero();
    os << "; still penetrating: " << (pair->kind == ContactPair::VertexFace ? "vertex-face" : "edge-edge")
       << " pair of nodes";
    for (int c = 0; c < 4; ++c) {
      os << " " << pair->gid[c] << " ('" << model.scene.bodies[pair->body[c]].name << "')";
      centre += 0.25 * pair->x[c];
    }
    os << " near (" << centre.x() << ", " << centre.y() << ", " << centre.z() << ")";
  }
  os << "; try a smaller time.safety or a larger contact.max_sweeps";
  return os.str();
}

std::string step_collapse_diagnosis(const Model& model, const StepCollapse& c, long step, double time) {
  const Mesh& mesh = model.mesh;
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: the stable step collapsed to " << c.dt
     << " s, below 1e-3 of the initial " << c.dt0 << " s (the run would crawl)";
  if (c.element < 0) return os.str() + "; try a smaller time.safety or a finer mesh";
  os << "; element " << mesh.elem_gid[c.element] << " (body '" << model.scene.bodies[mesh.elem_body[c.element]].name
     << "') near (" << c.centre.x() << ", " << c.centre.y() << ", " << c.centre.z() << ") sets it (stable step "
     << c.element_dt << " s, det F = " << c.J << ")";
  if (c.element_dt > 1.001 * c.dt) os << "; the cohesive elements' stiffness sets a smaller one";
  // The body's conditions that move (a non-zero component) or hold one of
  // the element's nodes (by reference position, as build_model applies them).
  const int body = mesh.elem_body[c.element];
  std::vector<std::string> driving;
  for (size_t j = 0; j < model.scene.boundary_conditions.size(); ++j) {
    const BoundaryConditionSpec& bc = model.scene.boundary_conditions[j];
    if (bc.body != body) continue;
    bool moves = false, holds = false;
    for (int k = 0; k < 3; ++k) moves = moves || (bc.value[k] && *bc.value[k] != 0);
    for (int a = 0; a < mesh.nodes_per_element(); ++a) {
      const auto& by = model.bc_condition[mesh.element(c.element)[a]];
      holds = holds || std::find(by.begin(), by.end(), static_cast<std::int32_t>(j)) != by.end();
    }
    if (!moves && !holds) continue;
    std::ostringstream v;
    v << bc.key << "." << bc.quantity() << " = [";
    for (int k = 0; k < 3; ++k) {
      v << (k ? ", " : "");
      if (bc.value[k]) v << *bc.value[k];
      else v << "null";
    }
    v << "] " << bc.unit() << (holds ? " on its nodes" : "");
    driving.push_back(v.str());
  }
  std::ostringstream shape;
  if (c.J < 0.5) shape << "it is crushed to " << c.J << " of its volume";
  else if (c.J > 2.0) shape << "it is stretched to " << c.J << " times its volume";
  else shape << "it is flattened (its shape collapsed, not its volume)";
  if (!driving.empty()) {
    os << "; likely cause: the velocities prescribed on its body (";
    for (size_t k = 0; k < driving.size(); ++k) os << (k ? ", " : "") << driving[k];
    os << ") and " << shape.str() << "; check those velocities against the body's size and wave speed";
  } else {
    os << "; likely cause: " << shape.str() << " (an impact or load too fast for the mesh); try a smaller "
       << "time.safety or a finer mesh";
  }
  return os.str();
}

std::string ledger_diagnosis(double overflow, const Model& model, std::span<const Vec3> x, std::span<const Vec3> v,
                             std::span<const Vec3> a, const Ledger& l, long step, double time) {
  const bool finite = std::isfinite(l.largest());
  std::ostringstream os;
  if (step == 0) os << "the initial state's energy ledger is ";
  else os << "step " << step << ", t = " << time << " s: the energy ledger is ";
  if (!finite) os << "not finite";
  else if (step == 0) os << "beyond " << overflow << " J";
  else os << "beyond " << overflow << " J, an overflow under way";
  os << " (kinetic " << l.kinetic << ", strain " << l.strain << ", cohesive " << l.cohesive_stored << " + "
     << l.cohesive_dissipated << ", contact " << l.contact_dissipated << " + " << l.contact_work << ", external work "
     << l.external_work << ")";
  const auto name = [&](size_t i) {
    os << "node " << model.mesh.node_gid[i] << " (body '" << model.scene.bodies[model.mesh.node_body[i]].name
       << "') at (" << x[i].x() << ", " << x[i].y() << ", " << x[i].z() << ") has velocity (" << v[i].x() << ", "
       << v[i].y() << ", " << v[i].z() << ")";
  };
  // The first node with a velocity or acceleration that is not finite; in an overflow, the fastest node.
  size_t bad = 0;
  while (bad < v.size() && v[bad].allFinite() && a[bad].allFinite()) ++bad;
  if (bad < v.size()) {
    os << "; ";
    name(bad);
  } else if (finite && !v.empty()) {
    size_t fastest = 0;
    for (size_t i = 1; i < v.size(); ++i)
      if (v[i].squaredNorm() > v[fastest].squaredNorm()) fastest = i;
    os << "; the fastest ";
    name(fastest);
  }
  if (step == 0)
    os << "; expected initial velocities (bodies[].initial_velocity, angular_velocity, velocity_gradient, "
          "boundary_conditions[].velocity) and densities whose energy a run can hold";
  else if (finite) os << "; check the scene's velocities, gravity and material constants";
  else os << "; try a smaller time.safety or a finer mesh";
  return os.str();
}

}  // namespace shatter
