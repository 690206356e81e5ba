#include "runtime/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "kernels/error.hpp"
#include "kernels/neo_hookean.hpp"

namespace shatter {
namespace {

// Reader of one scene file: every accessor checks type and range and names
// the key path in its message.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  /// Characters of a bad value quoted in a message.
  static constexpr std::size_t kMaxEcho = 200;

  [[noreturn]] void fail(const std::string& key, const std::string& expected, const YAML::Node& got) const {
    std::ostringstream os;
    os << file_ << ": " << key << ": expected " << expected;
    if (got.IsDefined() && !got.IsNull()) {
      YAML::Emitter e;  // one line: flow style all the way down
      e.SetMapFormat(YAML::Flow);
      e.SetSeqFormat(YAML::Flow);
      e << got;
      // A long value is cut (at a UTF-8 character's start): the message stays one readable line.
      std::string text = e.c_str();
      if (text.size() > kMaxEcho) {
        std::size_t cut = kMaxEcho;
        while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
        text = text.substr(0, cut) + "... (" + std::to_string(text.size()) + " characters)";
      }
      os << ", got '" << text << "'";
    } else {
      os << ", but it is missing";
    }
    throw InputError(os.str());
  }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InputError(file_ + ": " + key + ": " + message);
  }

  void only_keys(const YAML::Node& map, const std::string& key, std::initializer_list<const char*> allowed) const {
    if (!map.IsMap()) fail(key.empty() ? "(top level)" : key, "a mapping", map);
    std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : map) {
      const std::string k = string(kv.first, join(key, "(key)"));
      if (!ok.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(join(key, k), "unknown key; expected one of: " + list);
      }
    }
  }

  static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }

  double number(const YAML::Node& n, const std::string& key, const char* expected = "a number") const {
    if (!n.IsScalar()) fail(key, expected, n);
    double v = 0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, expected, n);
    }
    if (!std::isfinite(v)) fail(key, expected, n);
    return v;
  }
  double positive(const YAML::Node& n, const std::string& key) const {
    const double v = number(n, key, "a positive number");
    if (!(v > 0)) fail(key, "a positive number", n);
    return v;
  }
  long count(const YAML::Node& n, const std::string& key, long min) const {
    if (!n.IsScalar()) fail(key, "an integer >= " + std::to_string(min), n);
    try {
      const long v = n.as<long>();
      if (v < min) fail(key, "an integer >= " + std::to_string(min), n);
      return v;
    } catch (const YAML::Exception&) {
      fail(key, "an integer >= " + std::to_string(min), n);
    }
  }
  bool flag(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar() || (n.Scalar() != "true" && n.Scalar() != "false")) fail(key, "true or false", n);
    return n.Scalar() == "true";
  }
  std::string string(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar() || n.Scalar().empty()) fail(key, "a non-empty string", n);
    return n.as<std::string>();
  }
  Vec3 vec3(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() != 3) fail(key, "a list of 3 numbers [x, y, z]", n);
    return Vec3(number(n[0], key + "[0]"), number(n[1], key + "[1]"), number(n[2], key + "[2]"));
  }
  Mat3 mat3(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() != 3) fail(key, "a 3x3 matrix [[..],[..],[..]] in 1/s", n);
    Mat3 m;
    for (int i = 0; i < 3; ++i) m.row(i) = vec3(n[i], key + "[" + std::to_string(i) + "]").transpose();
    return m;
  }
  const YAML::Node required(const YAML::Node& map, const std::string& parent, const char* k) const {
    const YAML::Node n = map[k];
    if (!n.IsDefined() || n.IsNull()) fail(join(parent, k), "a value (required key)", n);
    return n;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// Walk a key path like bodies[0].mesh.element_size and return the node to set.
YAML::Node walk(YAML::Node root, const std::string& path, const std::string& file) {
  YAML::Node node = root;
  std::size_t i = 0;
  auto bad = [&](const std::string& why) {
    throw InputError("--set " + path + ": " + why + " (scene " + file + ")");
  };
  while (i < path.size()) {
    std::size_t j = path.find_first_of(".[", i);
    const std::string name = path.substr(i, j == std::string::npos ? std::string::npos : j - i);
    if (name.empty()) bad("expected a key path like time.safety or bodies[0].mesh.element_size");
    // yaml-cpp throws its own exception for a key into a value or a list.
    if (node.IsScalar() || node.IsSequence())
      bad("'" + (i == 0 ? std::string("(top level)") : path.substr(0, i - 1)) +
          "' is not a mapping");
    node.reset(node[name]);
    i = j == std::string::npos ? path.size() : j;
    while (i < path.size() && path[i] == '[') {
      const std::size_t close = path.find(']', i);
      if (close == std::string::npos) bad("unclosed '['");
      const std::string digits = path.substr(i + 1, close - i - 1);
      // stoul alone reads "0abc" and "0x1" as 0: only decimal digits are an index.
      if (digits.empty() || digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos)
        bad("expected a decimal index inside [ ], got '" + digits + "'");
      const std::size_t idx = std::stoul(digits);
      if (!node.IsSequence() || idx >= node.size()) bad("index " + std::to_string(idx) + " is out of range");
      node.reset(node[idx]);
      i = close + 1;
    }
    if (i < path.size() && path[i] == '.') ++i;
  }
  return node;
}

// yaml-cpp keeps every pair of a mapping with a repeated key, and a lookup
// finds the first while a loop sees both: a repeated key is refused, with
// both lines, wherever it is (`where` is the file, or the --set override).
// Only scalar keys are compared (only_keys refuses the others); a tree deeper
// than any scene (or an alias cycle, &a [*a]) is not descended further.
void refuse_duplicate_keys(const YAML::Node& node, const std::string& key, const std::string& where,
                           int depth = 0) {
  if (depth > 32) return;
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      refuse_duplicate_keys(node[i], key + "[" + std::to_string(i) + "]", where, depth + 1);
  } else if (node.IsMap()) {
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) continue;
      const std::string k = kv.first.Scalar();
      const std::string path = Reader::join(key, k);
      const auto [first, fresh] = seen.emplace(k, kv.first.Mark());
      if (!fresh) {
        const YAML::Mark at = kv.first.Mark();
        std::ostringstream os;
        os << where << ":" << at.line + 1 << ":" << at.column + 1 << ": " << path
           << ": duplicate key (first at line " << first->second.line + 1 << ":" << first->second.column + 1
           << "); expected each key once in a mapping";
        throw InputError(os.str());
      }
      refuse_duplicate_keys(kv.second, path, where, depth + 1);
    }
  }
}

void refuse_large_scene(std::uintmax_t bytes, const std::string& path) {
  if (bytes > kMaxSceneBytes)
    throw InputError(path + ": the scene file is " + std::to_string(bytes) + " bytes; expected at most " +
                     std::to_string(kMaxSceneBytes) + " (1 MiB: a scene names shapes, mesh files and numbers)");
}

// mesh.refine: a list of balls {center, radius, element_size}, each size at
// most the body's (a refinement, not a coarsening).
std::vector<RefineSpec> read_refine(const Reader& r, const YAML::Node& n, const std::string& key, double body_size) {
  if (!n.IsSequence() || n.size() == 0)
    r.fail(key, "a non-empty list of {center: [x, y, z], radius: r, element_size: h}", n);
  std::vector<RefineSpec> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    r.only_keys(n[i], k, {"center", "radius", "element_size"});
    RefineSpec f;
    f.center = r.vec3(r.required(n[i], k, "center"), k + ".center");
    f.radius = r.positive(r.required(n[i], k, "radius"), k + ".radius");
    f.element_size = r.positive(r.required(n[i], k, "element_size"), k + ".element_size");
    if (f.element_size > body_size) {
      std::ostringstream os;
      os << "a positive number at most the body's element_size " << body_size;
      r.fail(k + ".element_size", os.str(), n[i]["element_size"]);
    }
    out.push_back(f);
  }
  return out;
}

ShapeSpec read_shape(const Reader& r, const YAML::Node& m, const std::string& key) {
  ShapeSpec s;
  s.shape = r.string(r.required(m, key, "shape"), key + ".shape");
  if (s.shape == "box") {
    r.only_keys(m, key, {"shape", "size", "center", "element_size", "order", "notch", "refine"});
    s.size = r.vec3(r.required(m, key, "size"), key + ".size");
    if ((s.size.array() <= 0).any()) r.fail(key + ".size", "three positive lengths", m["size"]);
    if (const YAML::Node n = m["notch"]) {
      const std::string nk = key + ".notch";
      if (!n.IsMap()) r.fail(nk, "a map with center and size", n);
      r.only_keys(n, nk, {"center", "size"});
      s.notch_center = r.vec3(r.required(n, nk, "center"), nk + ".center");
      s.notch_size = r.vec3(r.required(n, nk, "size"), nk + ".size");
      if ((s.notch_size.array() <= 0).any()) r.fail(nk + ".size", "three positive lengths", n["size"]);
    }
  } else if (s.shape == "cylinder" || s.shape == "sphere") {
    if (s.shape == "cylinder")
      r.only_keys(m, key, {"shape", "radius", "length", "center", "axis", "element_size", "order", "refine"});
    else
      r.only_keys(m, key, {"shape", "radius", "inner_radius", "center", "element_size", "order", "refine"});
    s.radius = r.positive(r.required(m, key, "radius"), key + ".radius");
    if (s.shape == "cylinder") s.length = r.positive(r.required(m, key, "length"), key + ".length");
    if (s.shape == "sphere" && m["inner_radius"]) {
      s.inner_radius = r.positive(m["inner_radius"], key + ".inner_radius");
      if (s.inner_radius >= s.radius)
        r.fail(key + ".inner_radius", "a value smaller than radius (a hollow sphere)", m["inner_radius"]);
    }
  } else if (s.shape == "tube") {
    r.only_keys(m, key,
                {"shape", "inner_radius", "outer_radius", "length", "center", "axis", "element_size", "order",
                 "refine"});
    s.inner_radius = r.positive(r.required(m, key, "inner_radius"), key + ".inner_radius");
    s.outer_radius = r.positive(r.required(m, key, "outer_radius"), key + ".outer_radius");
    if (s.outer_radius <= s.inner_radius)
      r.fail(key + ".outer_radius", "a value larger than inner_radius", m["outer_radius"]);
    s.length = r.positive(r.required(m, key, "length"), key + ".length");
  } else {
    r.fail(key + ".shape", "one of box, cylinder, sphere, tube", m["shape"]);
  }
  if (m["center"]) s.center = r.vec3(m["center"], key + ".center");
  if (m["axis"]) {
    s.axis = r.vec3(m["axis"], key + ".axis");
    if (s.axis.norm() == 0) r.fail(key + ".axis", "a non-zero direction", m["axis"]);
  }
  s.element_size = r.positive(r.required(m, key, "element_size"), key + ".element_size");
  if (const YAML::Node n = m["refine"]) s.refine = read_refine(r, n, key + ".refine", s.element_size);
  return s;
}

/// A shell's mid-surface (bodies[i].mesh of a body with `shell`): sphere (its
/// surface), disk, rectangle or cylinder (its side), thinner than the shape.
ShellShapeSpec read_shell_shape(const Reader& r, const YAML::Node& m, const std::string& key, double thickness) {
  ShellShapeSpec s;
  s.shape = r.string(r.required(m, key, "shape"), key + ".shape");
  if (s.shape == "sphere" || s.shape == "disk") {
    r.only_keys(m, key, {"shape", "radius", "center", "element_size"});
  } else if (s.shape == "cylinder") {
    r.only_keys(m, key, {"shape", "radius", "length", "center", "axis", "element_size"});
    s.length = r.positive(r.required(m, key, "length"), key + ".length");
  } else if (s.shape == "rectangle") {
    r.only_keys(m, key, {"shape", "width", "height", "center", "element_size"});
    s.width = r.positive(r.required(m, key, "width"), key + ".width");
    s.height = r.positive(r.required(m, key, "height"), key + ".height");
  } else {
    r.fail(key + ".shape", "one of sphere, disk, rectangle, cylinder (a shell's mid-surface)", m["shape"]);
  }
  if (s.shape != "rectangle") s.radius = r.positive(r.required(m, key, "radius"), key + ".radius");
  if (m["center"]) s.center = r.vec3(m["center"], key + ".center");
  if (m["axis"]) {
    s.axis = r.vec3(m["axis"], key + ".axis");
    if (s.axis.norm() == 0) r.fail(key + ".axis", "a non-zero direction", m["axis"]);
  }
  s.element_size = r.positive(r.required(m, key, "element_size"), key + ".element_size");
  const double span = s.shape == "rectangle" ? std::min(s.width, s.height) : s.radius;
  if (thickness >= span) {
    std::ostringstream os;
    os << thickness << " is not below the shape's " << (s.shape == "rectangle" ? "shorter side " : "radius ") << span
       << " (" << key << "); expected a thin shell";
    r.fail(key.substr(0, key.rfind('.')) + ".shell.thickness", os.str());
  }
  return s;
}

StrengthScatter strength_scatter(const Reader& r, const YAML::Node& n, const std::string& key) {
  r.only_keys(n, key, {"distribution", "modulus", "spread", "seed", "reference_area"});
  StrengthScatter s;
  const std::string d = r.string(r.required(n, key, "distribution"), key + ".distribution");
  if (d == "weibull") {
    s.distribution = ScatterDistribution::weibull;
    s.modulus = r.positive(r.required(n, key, "modulus"), key + ".modulus");
    // Below 1 the draws span hundreds of decades (measured moduli are 3-50).
    if (s.modulus < 1) r.fail(key + ".modulus", "a Weibull modulus >= 1", n["modulus"]);
  } else if (d == "uniform") {
    s.distribution = ScatterDistribution::uniform;
    s.spread = r.number(r.required(n, key, "spread"), key + ".spread");
    if (!(s.spread >= 0 && s.spread < 1))
      r.fail(key + ".spread", "a half-width in [0, 1) as a fraction of the strength", n["spread"]);
  } else {
    r.fail(key + ".distribution", "one of weibull, uniform", n["distribution"]);
  }
  if (n["seed"]) s.seed = static_cast<std::uint64_t>(r.count(n["seed"], key + ".seed", 0));
  if (n["reference_area"]) s.reference_area = r.positive(n["reference_area"], key + ".reference_area");
  return s;
}


/// `region`: exactly one of box, physical, face; a face named by the body's shape.
RegionSpec read_region(const Reader& r, const YAML::Node& n, const std::string& key, const BodySpec& body) {
  r.only_keys(n, key, {"box", "physical", "face"});
  if (n.size() != 1) r.fail(key, "exactly one of box, physical, face", n);
  RegionSpec region;
  if (body.shell && !n["box"])
    r.fail(key, "{box: [[xmin, ymin, zmin], [xmax, ymax, zmax]]} for the shell body '" + body.name +
                    "' (its control vertices inside; shells have no named faces or groups yet)",
           n);
  if (const YAML::Node box = n["box"]) {
    const std::string bk = key + ".box";
    if (!box.IsSequence() || box.size() != 2) r.fail(bk, "[[xmin, ymin, zmin], [xmax, ymax, zmax]]", box);
    region.lo = r.vec3(box[0], bk + "[0]");
    region.hi = r.vec3(box[1], bk + "[1]");
    if ((region.lo.array() > region.hi.array()).any()) r.fail(bk, "min corner <= max corner", box);
  } else if (n["physical"]) {
    region.kind = RegionSpec::Kind::physical;
    region.name = r.string(n["physical"], key + ".physical");
    if (body.mesh_file.empty())
      r.fail(key + ".physical", "{face: NAME} for body '" + body.name + "', a shape (it has no physical groups)",
             n["physical"]);
  } else {
    region.kind = RegionSpec::Kind::face;
    region.name = r.string(n["face"], key + ".face");
    if (!body.mesh_file.empty())
      r.fail(key + ".face", "{physical: NAME} for body '" + body.name + "', read from a mesh file (its faces have no names)",
             n["face"]);
    const std::vector<std::string> names = shape_face_names(body.shape);
    if (std::find(names.begin(), names.end(), region.name) == names.end()) {
      std::string list;
      for (const std::string& f : names) list += (list.empty() ? "" : ", ") + f;
      r.fail(key + ".face", "a face of the " + body.shape.shape + " of body '" + body.name + "': one of " + list,
             n["face"]);
    }
  }
  return region;
}

/// `amplitude`: a table [[t0, a0], [t1, a1], ...] (times increasing), or one of
/// {ramp: t_r}, {smooth_step: [t0, t1]}, {half_sine: [t0, duration]}.
Amplitude read_amplitude(const Reader& r, const YAML::Node& n, const std::string& key) {
  const char* forms = "a table [[t0, a0], [t1, a1], ...] or one of {ramp: t_r}, {smooth_step: [t0, t1]}, "
                      "{half_sine: [t0, duration]}";
  Amplitude a;
  if (n.IsSequence()) {
    a.form = Amplitude::Form::table;
    if (n.size() < 2) r.fail(key, "a table of at least 2 points [[t0, a0], [t1, a1], ...]", n);
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      if (!n[i].IsSequence() || n[i].size() != 2) r.fail(k, "a point [t, a] (s, factor)", n[i]);
      const double t = r.number(n[i][0], k + "[0]"), v = r.number(n[i][1], k + "[1]");
      if (i > 0 && !(t > a.table.back()[0])) r.fail(k + "[0]", "a time after the previous point's", n[i][0]);
      a.table.push_back({t, v});
    }
    return a;
  }
  if (!n.IsMap() || n.size() != 1) r.fail(key, forms, n);
  r.only_keys(n, key, {"ramp", "smooth_step", "half_sine"});
  if (n["ramp"]) {
    a.form = Amplitude::Form::ramp;
    a.t1 = r.positive(n["ramp"], key + ".ramp");
    return a;
  }
  const bool smooth = static_cast<bool>(n["smooth_step"]);
  const std::string k = key + (smooth ? ".smooth_step" : ".half_sine");
  const YAML::Node pair = smooth ? n["smooth_step"] : n["half_sine"];
  if (!pair.IsSequence() || pair.size() != 2)
    r.fail(k, smooth ? "[t0, t1] (s), t0 < t1" : "[t0, duration] (s), duration > 0", pair);
  a.form = smooth ? Amplitude::Form::smooth_step : Amplitude::Form::half_sine;
  a.t0 = r.number(pair[0], k + "[0]");
  if (smooth) {
    a.t1 = r.number(pair[1], k + "[1]");
    if (!(a.t1 > a.t0)) r.fail(k + "[1]", "an end time after t0", pair[1]);
  } else {
    a.t1 = a.t0 + r.positive(pair[1], k + "[1]");
  }
  return a;
}

/// The body named by `key`.body.
int read_body_name(const Reader& r, const YAML::Node& c, const std::string& key, const Scene& s) {
  const std::string body = r.string(r.required(c, key, "body"), key + ".body");
  for (std::size_t k = 0; k < s.bodies.size(); ++k)
    if (s.bodies[k].name == body) return static_cast<int>(k);
  r.fail(key + ".body", "the name of a body", c["body"]);
}

/// What a condition or a load (`key`, a mapping with `keys`) acts on: its body and region.
template <class Spec>
Spec read_acting_on(const Reader& r, const YAML::Node& c, const std::string& key, const Scene& s,
                    std::initializer_list<const char*> keys) {
  r.only_keys(c, key, keys);
  Spec spec;
  spec.key = key;
  spec.body = read_body_name(r, c, key, s);
  spec.region = read_region(r, r.required(c, key, "region"), key + ".region", s.bodies[spec.body]);
  return spec;
}

/// Whether `c` gives key a (else b): exactly one of them, `expected` describing both.
bool read_either(const Reader& r, const YAML::Node& c, const std::string& key, const char* a, const char* b,
                 const std::string& expected) {
  if (c[a] && c[b]) r.fail(key, std::string("expected one of ") + a + " or " + b + ", not both");
  if (!c[a] && !c[b]) r.fail(key, "expected one of " + expected + " (a required key)");
  return static_cast<bool>(c[a]);
}

}  // namespace

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(path + ": the scene file does not exist or is not a file");
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec) refuse_large_scene(bytes, path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(path + ": the scene file cannot be read");
  return parse_scene(text.str(), path, overrides);
}

Scene parse_scene(const std::string& text, const std::string& path, const std::vector<std::string>& overrides) {
  refuse_large_scene(text.size(), path);
  Reader r(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream os;
    os << path << ":" << e.mark.line + 1 << ":" << e.mark.column + 1 << ": not valid YAML: " << e.msg;
    throw InputError(os.str());
  }
  refuse_duplicate_keys(root, "", path);
  for (const std::string& o : overrides) {
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set " + o + ": expected key.path=value");
    YAML::Node target = walk(root, o.substr(0, eq), path);
    YAML::Node value;
    try {
      value = YAML::Load(o.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw InputError("--set " + o + ": the value is not valid YAML: " + e.msg);
    }
    refuse_duplicate_keys(value, o.substr(0, eq), "--set " + o);
    target = value;
  }
  r.only_keys(root, "", {"name", "time", "output", "materials", "bodies", "boundary_conditions", "loads", "contact",
                         "gravity", "checkpoint"});
  Scene s;
  s.file = path;
  s.name = r.string(r.required(root, "", "name"), "name");
  if (s.name.find('/') != std::string::npos || s.name == "." || s.name == "..")
    r.fail("name", "a plain name usable as a folder name (no '/')", root["name"]);

  const YAML::Node time = r.required(root, "", "time");
  r.only_keys(time, "time", {"end", "dt", "safety", "fracture_check_every"});
  s.end_time = r.positive(r.required(time, "time", "end"), "time.end");
  if (time["dt"]) s.fixed_dt = r.positive(time["dt"], "time.dt");
  if (time["safety"]) {
    s.safety = r.positive(time["safety"], "time.safety");
    if (s.safety > 1.0) r.fail("time.safety", "a fraction of the stable step in (0, 1]", time["safety"]);
  }
  if (time["fracture_check_every"])
    s.fracture_check_every = r.count(time["fracture_check_every"], "time.fracture_check_every", 1);

  if (const YAML::Node out = root["output"]) {
    r.only_keys(out, "output", {"every", "history_every"});
    if (out["every"]) s.output_every = r.count(out["every"], "output.every", 0);
    if (out["history_every"]) s.history_every = r.count(out["history_every"], "output.history_every", 1);
  }

  const YAML::Node mats = r.required(root, "", "materials");
  if (!mats.IsMap() || mats.size() == 0) r.fail("materials", "a mapping of material names to materials", mats);
  for (const auto& kv : mats) {
    MaterialSpec m;
    m.name = r.string(kv.first, "materials.(name)");
    const std::string key = "materials." + m.name;
    const YAML::Node n = kv.second;
    r.only_keys(n, key, {"model", "density", "youngs_modulus", "poisson_ratio", "fracture"});
    m.model = r.string(r.required(n, key, "model"), key + ".model");
    if (m.model != "neo_hookean") r.fail(key + ".model", "neo_hookean (the only model so far)", n["model"]);
    m.density = r.positive(r.required(n, key, "density"), key + ".density");
    m.young = r.positive(r.required(n, key, "youngs_modulus"), key + ".youngs_modulus");
    m.poisson = r.number(r.required(n, key, "poisson_ratio"), key + ".poisson_ratio");
    if (!(m.poisson > -1.0 && m.poisson < 0.5))
      r.fail(key + ".poisson_ratio", "a Poisson ratio in (-1, 0.5)", n["poisson_ratio"]);
    // The wave speed sets the stable step: an infinite one (E = 1e308
    // overflows lambda + 2 mu; density 1e-300) gives a step of 0, a huge one a
    // step that never reaches time.end. No elastic wave outruns light.
    const double c = NeoHookean::from_young_poisson(m.young, m.poisson, m.density).wave_speed();
    if (!(c <= kMaxWaveSpeed)) {
      std::ostringstream os;
      os << "the dilatational wave speed sqrt((lambda + 2 mu) / density) from youngs_modulus " << m.young
         << ", poisson_ratio " << m.poisson << " and density " << m.density << " is " << c
         << " m/s; expected at most 3e8 m/s (the speed of light; steel's is 5.9e3 m/s)";
      r.fail(key, os.str());
    }
    if (const YAML::Node f = n["fracture"]) {
      const std::string fk = key + ".fracture";
      r.only_keys(f, fk, {"strength", "energy", "beta", "scatter"});
      FractureSpec fs;
      fs.strength = r.positive(r.required(f, fk, "strength"), fk + ".strength");
      fs.energy = r.positive(r.required(f, fk, "energy"), fk + ".energy");
      if (f["beta"]) fs.beta = r.positive(f["beta"], fk + ".beta");
      if (f["scatter"]) fs.scatter = strength_scatter(r, f["scatter"], fk + ".scatter");
      m.fracture = fs;
    }
    s.materials.push_back(m);
  }

  const YAML::Node bodies = r.required(root, "", "bodies");
  if (!bodies.IsSequence() || bodies.size() == 0) r.fail("bodies", "a non-empty list of bodies", bodies);
  const std::filesystem::path scene_dir = std::filesystem::path(path).parent_path();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::string key = "bodies[" + std::to_string(i) + "]";
    const YAML::Node b = bodies[i];
    r.only_keys(b, key,
                {"name", "material", "mesh", "shell", "initial_velocity", "angular_velocity", "velocity_gradient",
                 "rigid"});
    BodySpec body;
    body.key = key;
    body.name = b["name"] ? r.string(b["name"], key + ".name") : "body" + std::to_string(i);
    for (const auto& other : s.bodies)
      if (other.name == body.name) r.fail(key + ".name", "a name no other body has", b["name"]);
    const std::string mat = r.string(r.required(b, key, "material"), key + ".material");
    body.material = -1;
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (s.materials[m].name == mat) body.material = static_cast<int>(m);
    if (body.material < 0) r.fail(key + ".material", "the name of a material under 'materials'", b["material"]);
    const YAML::Node mesh = r.required(b, key, "mesh");
    const std::string mk = key + ".mesh";
    if (!mesh.IsMap()) r.fail(mk, "a mapping with either 'file' or 'shape'", mesh);
    if (mesh["file"] && mesh["shape"]) r.fail(mk, "exactly one of 'file' or 'shape', not both");
    if (const YAML::Node shell = b["shell"]) {
      const std::string sk = key + ".shell";
      if (!shell.IsMap()) r.fail(sk, "a mapping {thickness: t}", shell);
      r.only_keys(shell, sk, {"thickness"});
      ShellSpec spec;
      spec.thickness = r.positive(r.required(shell, sk, "thickness"), sk + ".thickness");
      if (mesh["file"])
        r.fail(mk + ".file", "expected a shape (sphere, disk, rectangle, cylinder) for the shell body '" + body.name +
                                 "': .msh files of shells are not read yet");
      if (!mesh["shape"]) r.fail(mk, "expected a shape (sphere, disk, rectangle, cylinder): the shell's mid-surface");
      spec.shape = read_shell_shape(r, mesh, mk, spec.thickness);
      if (s.materials[body.material].fracture)
        r.fail(key + ".material",
               "a material without a fracture block for the shell body '" + body.name + "' (shells do not fracture yet)",
               b["material"]);
      if (b["rigid"])
        r.fail(key + ".rigid", "no rigid key for the shell body '" + body.name + "' (rigid shells are not supported yet)",
               b["rigid"]);
      body.shell = spec;
    } else if (mesh["file"]) {
      r.only_keys(mesh, mk, {"file", "physical", "order"});
      const std::filesystem::path f = r.string(mesh["file"], mk + ".file");
      body.mesh_file = (f.is_absolute() ? f : scene_dir / f).string();
      if (mesh["physical"]) body.mesh_physical = r.string(mesh["physical"], mk + ".physical");
    } else if (mesh["shape"]) {
      body.shape = read_shape(r, mesh, mk);
    } else {
      r.fail(mk, "exactly one of 'file' (a Gmsh .msh) or 'shape' (box, cylinder, sphere, tube)");
    }
    if (mesh["order"]) {
      const long order = r.count(mesh["order"], mk + ".order", 1);
      if (order > 2) r.fail(mk + ".order", "1 (4-node tets) or 2 (10-node tets)", mesh["order"]);
      body.shape.order = static_cast<int>(order);
    }
    if (b["initial_velocity"]) body.initial_velocity = r.vec3(b["initial_velocity"], key + ".initial_velocity");
    if (b["angular_velocity"]) body.angular_velocity = r.vec3(b["angular_velocity"], key + ".angular_velocity");
    if (b["velocity_gradient"]) body.velocity_gradient = r.mat3(b["velocity_gradient"], key + ".velocity_gradient");
    if (const YAML::Node rigid = b["rigid"]) {
      if (!rigid.IsScalar() || (rigid.Scalar() != "true" && rigid.Scalar() != "false" && rigid.Scalar() != "free"))
        r.fail(key + ".rigid", "true, false or free", rigid);
      body.rigid = rigid.Scalar() == "true";
      body.free_rigid = rigid.Scalar() == "free";
      if (body.any_rigid() && body.velocity_gradient)
        r.fail(key + ".rigid",
               "false with velocity_gradient (a rigid body moves with initial_velocity and angular_velocity)",
               rigid);
    }
    s.bodies.push_back(body);
  }
  const auto first_solid = std::find_if(s.bodies.begin(), s.bodies.end(), [](const BodySpec& b) { return !b.shell; });
  for (const auto& b : s.bodies)
    if (b.mesh_file.empty() && !b.shell && b.shape.order != first_solid->shape.order)
      r.fail(b.key + ".mesh.order", "the same element order for every body");

  // A rigid body: its initial velocity prescribed on every node, before any condition.
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (!s.bodies[i].rigid) continue;
    BoundaryConditionSpec bc;
    bc.key = s.bodies[i].key + ".rigid";
    bc.body = static_cast<int>(i);
    bc.region.lo = Vec3::Constant(-HUGE_VAL);
    bc.region.hi = Vec3::Constant(HUGE_VAL);
    for (int k = 0; k < 3; ++k) bc.value[k] = s.bodies[i].initial_velocity[k];
    s.boundary_conditions.push_back(bc);
  }
  if (const YAML::Node bcs = root["boundary_conditions"]) {
    if (!bcs.IsSequence()) r.fail("boundary_conditions", "a list of boundary conditions", bcs);
    for (std::size_t i = 0; i < bcs.size(); ++i) {
      const std::string key = "boundary_conditions[" + std::to_string(i) + "]";
      const YAML::Node c = bcs[i];
      BoundaryConditionSpec bc = read_acting_on<BoundaryConditionSpec>(
          r, c, key, s, {"body", "region", "velocity", "displacement", "amplitude", "clamped"});
      bc.displacement = !read_either(r, c, key, "velocity", "displacement",
                                     "velocity [vx, vy, vz] or displacement [ux, uy, uz]");
      const std::string vk = key + "." + bc.quantity();
      const YAML::Node v = c[bc.quantity()];
      if (!v.IsSequence() || v.size() != 3)
        r.fail(vk, std::string(bc.displacement ? "[ux, uy, uz]" : "[vx, vy, vz]") + " with null for free components",
               v);
      bool any = false;
      for (int k = 0; k < 3; ++k)
        if (!v[k].IsNull()) {
          bc.value[k] = r.number(v[k], vk + "[" + std::to_string(k) + "]");
          any = true;
        }
      if (!any) r.fail(vk, "at least one prescribed (non-null) component", v);
      if (c["amplitude"]) bc.amplitude = read_amplitude(r, c["amplitude"], key + ".amplitude");
      if (c["clamped"]) {
        bc.clamped = r.flag(c["clamped"], key + ".clamped");
        if (bc.clamped && !s.bodies[bc.body].shell)
          r.fail(key + ".clamped", "no clamped key for the solid body '" + s.bodies[bc.body].name +
                                       "' (a clamp turns a shell's edge; a solid's held nodes are clamped already)",
                 c["clamped"]);
        if (bc.clamped && !(bc.value[0] && bc.value[1] && bc.value[2]))
          r.fail(vk, "all three components prescribed on a clamped edge", v);
      }
      if (s.bodies[bc.body].free_rigid)
        r.fail(key + ".body",
               "a body that is not rigid: free (a free rigid body moves by its momenta; rigid: true prescribes its "
               "velocity)",
               c["body"]);
      s.boundary_conditions.push_back(bc);
    }
  }

  if (const YAML::Node loads = root["loads"]) {
    if (!loads.IsSequence()) r.fail("loads", "a list of loads {body, region, pressure or traction, amplitude}", loads);
    for (std::size_t i = 0; i < loads.size(); ++i) {
      const std::string key = "loads[" + std::to_string(i) + "]";
      const YAML::Node c = loads[i];
      LoadSpec load =
          read_acting_on<LoadSpec>(r, c, key, s, {"body", "region", "pressure", "traction", "amplitude"});
      if (read_either(r, c, key, "pressure", "traction", "pressure (Pa) or traction ([tx, ty, tz], Pa)"))
        load.pressure = r.number(c["pressure"], key + ".pressure");
      else
        load.traction = r.vec3(c["traction"], key + ".traction");
      if (c["amplitude"]) load.amplitude = read_amplitude(r, c["amplitude"], key + ".amplitude");
      if (s.bodies[load.body].shell)
        r.fail(key + ".body",
               "a solid body: '" + s.bodies[load.body].name + "' is a shell (loads on shells are not supported yet)",
               c["body"]);
      s.loads.push_back(load);
    }
  }

  if (const YAML::Node c = root["contact"]) {
    ContactSpec cs;
    if (!c.IsNull()) {
      r.only_keys(c, "contact",
                  {"friction", "restitution", "max_sweeps", "search_margin", "placement", "on_sweep_cap", "pairs", "self"});
      if (const YAML::Node p = c["pairs"]) {
        if (!p.IsSequence() || p.size() == 0) r.fail("contact.pairs", "a list of body name pairs [[a, b], ...]", p);
        for (std::size_t k = 0; k < p.size(); ++k) {
          const std::string key = "contact.pairs[" + std::to_string(k) + "]";
          if (!p[k].IsSequence() || p[k].size() != 2) r.fail(key, "a pair of body names [a, b]", p[k]);
          std::array<int, 2> pair{};
          for (int j = 0; j < 2; ++j) {
            const std::string name = r.string(p[k][j], key + "[" + std::to_string(j) + "]");
            pair[j] = -1;
            for (std::size_t b = 0; b < s.bodies.size(); ++b)
              if (s.bodies[b].name == name) pair[j] = static_cast<int>(b);
            if (pair[j] < 0) r.fail(key + "[" + std::to_string(j) + "]", "the name of a body", p[k][j]);
          }
          cs.pairs.push_back({std::min(pair[0], pair[1]), std::max(pair[0], pair[1])});
        }
        std::sort(cs.pairs.begin(), cs.pairs.end());
        cs.pairs.erase(std::unique(cs.pairs.begin(), cs.pairs.end()), cs.pairs.end());
      }
      if (const YAML::Node self = c["self"]) {
        cs.self = r.flag(self, "contact.self");
        for (const auto& [a, b] : cs.pairs)
          if (!cs.self && a == b)
            r.fail("contact.self", "true when contact.pairs lists a body with itself ('" + s.bodies[a].name + "')",
                   self);
      }
      if (c["friction"]) {
        cs.friction = r.number(c["friction"], "contact.friction");
        if (cs.friction < 0) r.fail("contact.friction", "a Coulomb coefficient >= 0", c["friction"]);
      }
      if (c["restitution"]) {
        cs.restitution = r.number(c["restitution"], "contact.restitution");
        if (cs.restitution < 0 || cs.restitution > 1) r.fail("contact.restitution", "a value in [0, 1]", c["restitution"]);
      }
      if (c["max_sweeps"]) {
        const long sweeps = r.count(c["max_sweeps"], "contact.max_sweeps", 1);
        if (sweeps > 1000000) r.fail("contact.max_sweeps", "an integer in [1, 1000000]", c["max_sweeps"]);
        cs.max_sweeps = static_cast<int>(sweeps);
      }
      if (c["on_sweep_cap"]) {
        const std::string what = r.string(c["on_sweep_cap"], "contact.on_sweep_cap");
        if (what != "warn" && what != "fail") r.fail("contact.on_sweep_cap", "warn or fail", c["on_sweep_cap"]);
        cs.sweep_cap_fatal = what == "fail";
      }
      if (c["search_margin"]) {
        cs.search_margin = r.number(c["search_margin"], "contact.search_margin");
        if (!(cs.search_margin >= 0))
          r.fail("contact.search_margin", "a fraction of the median surface edge >= 0", c["search_margin"]);
      }
      if (c["placement"]) {
        const std::string p = r.string(c["placement"], "contact.placement");
        if (p != "end" && p != "middle" && p != "impact")
          r.fail("contact.placement", "one of end, middle, impact", c["placement"]);
        cs.placement = p == "end"      ? DcrPlacement::End
                       : p == "middle" ? DcrPlacement::Middle
                                       : DcrPlacement::Impact;
      }
    }
    for (std::size_t a = 0; a < s.bodies.size(); ++a)
      for (std::size_t b = a + 1; b < s.bodies.size(); ++b)
        if (s.bodies[a].free_rigid && s.bodies[b].free_rigid &&
            (cs.pairs.empty() || std::binary_search(cs.pairs.begin(), cs.pairs.end(),
                                                    std::array<int, 2>{static_cast<int>(a), static_cast<int>(b)})))
          r.fail("contact.pairs",
                 "the free rigid bodies '" + s.bodies[a].name + "' and '" + s.bodies[b].name +
                     "' may touch; list the pairs that touch without theirs (DCR moves one rigid body per pair)");
    s.contact = cs;
  }
  if (root["gravity"]) s.gravity = r.vec3(root["gravity"], "gravity");
  if (!s.fixed_dt && std::all_of(s.bodies.begin(), s.bodies.end(), [](const BodySpec& b) { return b.any_rigid(); }))
    r.fail("time.dt", "missing, but every body is rigid and rigid bodies' elements set no stable step: give a "
                      "fixed step");
  if (const YAML::Node c = root["checkpoint"]) {
    r.only_keys(c, "checkpoint", {"every_steps", "every_seconds"});
    CheckpointSpec cp;
    if (c["every_steps"]) cp.every_steps = r.count(c["every_steps"], "checkpoint.every_steps", 1);
    if (c["every_seconds"]) cp.every_seconds = r.positive(c["every_seconds"], "checkpoint.every_seconds");
    s.checkpoint = cp;
  }
  return s;
}

}  // namespace shatter
