#include "runtime/diagnosis.hpp"

#include <sstream>

namespace shatter {

std::string sweep_cap_diagnosis(const Model& model, std::span<const Vec3> x, const ContactPairs& pairs,
                                const DcrResult& r, long step, double time) {
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: DCR sweeps reached the cap (contact.max_sweeps = "
     << model.scene.contact->max_sweeps << ") with penetrations left (contact.on_sweep_cap: fail)";
  if (r.unresolved >= 0 && static_cast<size_t>(r.unresolved) < pairs.size()) {
    const ContactPair& p = pairs[r.unresolved];
    Vec3 centre = Vec3::Zero();
    os << "; still penetrating: " << (p.kind == ContactPair::VertexFace ? "vertex-face" : "edge-edge")
       << " pair of nodes";
    for (const Index n : p.nodes) {
      os << " " << model.mesh.node_gid[n] << " ('" << model.scene.bodies[model.mesh.node_body[n]].name << "')";
      centre += 0.25 * x[n];
    }
    os << " near (" << centre.x() << ", " << centre.y() << ", " << centre.z() << ")";
  }
  os << "; try a smaller time.safety or a larger contact.max_sweeps";
  return os.str();
}

std::string non_finite_diagnosis(const Model& model, std::span<const Vec3> x, std::span<const Vec3> v,
                                 std::span<const Vec3> a, const Ledger& l, long step, double time) {
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: the energy ledger is not finite (kinetic " << l.kinetic
     << ", strain " << l.strain << ", cohesive " << l.cohesive_stored << " + " << l.cohesive_dissipated
     << ", contact " << l.contact_dissipated << ", external work " << l.external_work << ")";
  for (size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite() || !a[i].allFinite()) {
      os << "; node " << model.mesh.node_gid[i] << " (body '" << model.scene.bodies[model.mesh.node_body[i]].name
         << "') at (" << x[i].x() << ", " << x[i].y() << ", " << x[i].z() << ") has velocity (" << v[i].x() << ", "
         << v[i].y() << ", " << v[i].z() << ")";
      break;
    }
  os << "; try a smaller time.safety or a finer mesh";
  return os.str();
}

}  // namespace shatter
