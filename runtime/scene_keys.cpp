#include "runtime/scene_keys.hpp"

#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <vector>

namespace shatter {
namespace {

class KeyWriter {
 public:
  void number(const std::string& key, double v) {
    // The shortest of %.15g and %.17g that reads back as v: exact, and 0.3 not 0.29999999999999999.
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.15g", v);
    if (std::strtod(buf, nullptr) != v) std::snprintf(buf, sizeof buf, "%.17g", v);
    text(key, buf);
  }
  void integer(const std::string& key, long v) { text(key, std::to_string(v)); }
  void vec3(const std::string& key, const Vec3& v) {
    for (int c = 0; c < 3; ++c) number(key + "[" + std::to_string(c) + "]", v[c]);
  }
  void text(const std::string& key, const std::string& v) { out_ << key << '=' << v << '\n'; }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

/// A box as before regions had names (a checkpoint's keys stay comparable).
void region_keys(KeyWriter& w, const RegionSpec& r, const std::string& key) {
  if (r.kind == RegionSpec::Kind::box) {
    w.vec3(key + ".box[0]", r.lo);
    w.vec3(key + ".box[1]", r.hi);
  } else {
    w.text(key + (r.kind == RegionSpec::Kind::physical ? ".physical" : ".face"), r.name);
  }
}

/// Nothing for the constant amplitude (the keys of scenes before amplitudes).
void amplitude_keys(KeyWriter& w, const Amplitude& a, const std::string& key) {
  switch (a.form) {
    case Amplitude::Form::constant:
      return;
    case Amplitude::Form::table:
      for (size_t k = 0; k < a.table.size(); ++k) {
        w.number(key + "[" + std::to_string(k) + "][0]", a.table[k][0]);
        w.number(key + "[" + std::to_string(k) + "][1]", a.table[k][1]);
      }
      return;
    case Amplitude::Form::ramp:
      w.number(key + ".ramp", a.t1);
      return;
    case Amplitude::Form::smooth_step:
      w.number(key + ".smooth_step[0]", a.t0);
      w.number(key + ".smooth_step[1]", a.t1);
      return;
    case Amplitude::Form::half_sine:
      w.number(key + ".half_sine[0]", a.t0);
      w.number(key + ".half_sine[1]", a.t1 - a.t0);
      return;
  }
}

void shape_keys(KeyWriter& w, const ShapeSpec& s, const std::string& key) {
  w.text(key + ".shape", s.shape);
  w.vec3(key + ".size", s.size);
  w.number(key + ".radius", s.radius);
  w.number(key + ".inner_radius", s.inner_radius);
  w.number(key + ".outer_radius", s.outer_radius);
  w.number(key + ".length", s.length);
  w.vec3(key + ".center", s.center);
  w.vec3(key + ".axis", s.axis);
  w.number(key + ".element_size", s.element_size);
  w.vec3(key + ".notch.center", s.notch_center);
  w.vec3(key + ".notch.size", s.notch_size);
  for (std::size_t i = 0; i < s.refine.size(); ++i) {
    const std::string k = key + ".refine[" + std::to_string(i) + "]";
    w.vec3(k + ".center", s.refine[i].center);
    w.number(k + ".radius", s.refine[i].radius);
    w.number(k + ".element_size", s.refine[i].element_size);
  }
}

std::map<std::string, std::string> lines_by_key(const std::string& text, std::vector<std::string>& order) {
  std::map<std::string, std::string> m;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find('=');
    const std::string key = line.substr(0, eq);
    if (!m.count(key)) order.push_back(key);
    m[key] = eq == std::string::npos ? "" : line.substr(eq + 1);
  }
  return m;
}

}  // namespace

std::string physics_keys(const Scene& s) {
  KeyWriter w;
  w.integer("time.fracture_check_every", s.fracture_check_every);
  for (const MaterialSpec& m : s.materials) {
    const std::string key = "materials." + m.name;
    w.text(key + ".model", m.model);
    w.number(key + ".density", m.density);
    w.number(key + ".youngs_modulus", m.young);
    w.number(key + ".poisson_ratio", m.poisson);
    if (m.fracture) {
      w.number(key + ".fracture.strength", m.fracture->strength);
      w.number(key + ".fracture.energy", m.fracture->energy);
      w.number(key + ".fracture.beta", m.fracture->beta);
      if (const auto& sc = m.fracture->scatter) {
        const std::string sk = key + ".fracture.scatter";
        const bool weibull = sc->distribution == ScatterDistribution::weibull;
        w.text(sk + ".distribution", weibull ? "weibull" : "uniform");
        w.number(sk + (weibull ? ".modulus" : ".spread"), weibull ? sc->modulus : sc->spread);
        w.text(sk + ".seed", std::to_string(sc->seed));
        if (weibull) w.number(sk + ".reference_area", sc->reference_area);
      }
    }
  }
  for (const BodySpec& b : s.bodies) {
    w.text(b.key + ".name", b.name);
    w.text(b.key + ".material", s.materials[b.material].name);
    if (b.shell) {
      const ShellShapeSpec& m = b.shell->shape;
      const std::string mk = b.key + ".mesh";
      w.number(b.key + ".shell.thickness", b.shell->thickness);
      w.text(mk + ".shape", m.shape);
      w.number(mk + ".radius", m.radius);
      w.number(mk + ".length", m.length);
      w.number(mk + ".width", m.width);
      w.number(mk + ".height", m.height);
      w.vec3(mk + ".center", m.center);
      w.vec3(mk + ".axis", m.axis);
      w.number(mk + ".element_size", m.element_size);
    } else if (b.mesh_file.empty())
      shape_keys(w, b.shape, b.key + ".mesh");
    else
      w.text(b.key + ".mesh.physical", b.mesh_physical);
    w.integer(b.key + ".mesh.order", b.shape.order);
    w.vec3(b.key + ".initial_velocity", b.initial_velocity);
    w.vec3(b.key + ".angular_velocity", b.angular_velocity);
    // rigid: true is its condition's keys; free only where set (older checkpoints' texts stay equal).
    if (b.free_rigid) w.text(b.key + ".rigid", "free");
    if (b.velocity_gradient)
      for (int i = 0; i < 3; ++i)
        w.vec3(b.key + ".velocity_gradient[" + std::to_string(i) + "]", b.velocity_gradient->row(i).transpose());
  }
  for (const BoundaryConditionSpec& c : s.boundary_conditions) {
    w.text(c.key + ".body", s.bodies[c.body].name);
    region_keys(w, c.region, c.key + ".region");
    for (int k = 0; k < 3; ++k) {
      const std::string key = c.key + "." + c.quantity() + "[" + std::to_string(k) + "]";
      if (c.value[k])
        w.number(key, *c.value[k]);
      else
        w.text(key, "null");
    }
    amplitude_keys(w, c.amplitude, c.key + ".amplitude");
    if (c.clamped) w.text(c.key + ".clamped", "true");
  }
  for (const LoadSpec& l : s.loads) {
    w.text(l.key + ".body", s.bodies[l.body].name);
    region_keys(w, l.region, l.key + ".region");
    if (l.pressure) w.number(l.key + ".pressure", *l.pressure);
    if (l.traction) w.vec3(l.key + ".traction", *l.traction);
    amplitude_keys(w, l.amplitude, l.key + ".amplitude");
  }
  w.text("contact", s.contact ? "on" : "off");
  if (s.contact) {
    const ContactSpec& c = *s.contact;
    w.number("contact.friction", c.friction);
    w.number("contact.restitution", c.restitution);
    w.integer("contact.max_sweeps", c.max_sweeps);
    w.number("contact.search_margin", c.search_margin);
    const DcrPlacement p = c.placement;
    w.text("contact.placement", p == DcrPlacement::End ? "end" : p == DcrPlacement::Middle ? "middle" : "impact");
    w.text("contact.on_sweep_cap", c.sweep_cap_fatal ? "fail" : "warn");
    w.text("contact.self", c.self ? "true" : "false");
  }
  w.vec3("gravity", s.gravity);
  return w.str();
}

KeyDifference first_difference(const std::string& a, const std::string& b) {
  std::vector<std::string> order;
  const auto ma = lines_by_key(a, order);
  const auto mb = lines_by_key(b, order);
  for (const std::string& key : order) {
    const auto ia = ma.find(key), ib = mb.find(key);
    const std::string va = ia == ma.end() ? "(none)" : ia->second;
    const std::string vb = ib == mb.end() ? "(none)" : ib->second;
    if (va != vb) return {key, va, vb};
  }
  return {};
}

}  // namespace shatter
