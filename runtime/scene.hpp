#pragma once
// Scene files (the contract in SCENE.md): loaded with yaml-cpp, checked
// strictly before anything runs. Every error is an InputError naming the
// file, the key path (bodies[1].mesh.radius) and what was expected.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fracture/strength_scatter.hpp"
#include "kernels/amplitude.hpp"
#include "kernels/dcr.hpp"
#include "kernels/types.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/shell_gmsh.hpp"
#include "runtime/regions.hpp"

namespace shatter {

struct FractureSpec {
  double strength = 0;  ///< sigma_c, Pa
  double energy = 0;    ///< Gc, J/m^2
  double beta = 1.0;    ///< shear/normal strength ratio
  std::optional<StrengthScatter> scatter;  ///< per-facet strength (fracture.scatter)
};

struct MaterialSpec {
  std::string name;
  std::string model;     ///< neo_hookean
  double density = 0;    ///< kg/m^3
  double young = 0;      ///< Pa
  double poisson = 0;
  std::optional<FractureSpec> fracture;
};

/// bodies[i].shell: the body is a thin shell (docs/shells.md): its mesh is the
/// control mesh of its mid-surface, meshed from `shape` (mesh.shape).
struct ShellSpec {
  double thickness = 0;  ///< m
  ShellShapeSpec shape;  ///< the mid-surface: sphere (its surface), disk, rectangle, cylinder (its side)
};

struct BodySpec {
  std::string name;
  int material = 0;            ///< index into Scene::materials
  std::string mesh_file;       ///< .msh path (resolved against the scene's folder); empty: shape
  std::string mesh_physical;   ///< optional physical volume name in the file
  ShapeSpec shape;
  Vec3 initial_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  std::optional<Mat3> velocity_gradient;
  /// bodies[i].shell: a thin shell (its ShapeSpec `shape` is unused); none: a solid.
  std::optional<ShellSpec> shell;
  /// bodies[i].rigid: true: the body moves with its initial velocity for ever (a condition
  /// "bodies[i].rigid" prescribing it on every node, first in Scene::boundary_conditions),
  /// spinning at angular_velocity about its centre of mass (runtime/rigid_bodies.hpp places
  /// its nodes): infinite mass in DCR, its contact impulses' work in external_work.
  bool rigid = false;
  /// bodies[i].rigid: free: a free rigid body, one particle with the mass, centre and inertia
  /// of its lumped masses (kernels/rigid_body.hpp, runtime/rigid_bodies.hpp): it translates and
  /// spins under gravity, loads and contact (DCR moves it as a whole); `rigid` stays false.
  bool free_rigid = false;
  /// rigid or free_rigid: its elements are never computed (their forces are 0).
  bool any_rigid() const { return rigid || free_rigid; }
  /// A rigid body whose state RigidBodies keeps: a free one, or a prescribed one that spins
  /// (a prescribed translation alone is its condition's).
  bool has_rigid_state() const { return free_rigid || (rigid && angular_velocity != Vec3::Zero()); }
  std::string key;             ///< "bodies[i]", for messages
};

struct BoundaryConditionSpec {
  int body = 0;
  RegionSpec region;                           ///< the nodes it prescribes
  bool displacement = false;                   ///< `value` is a displacement (m), else a velocity (m/s)
  std::array<std::optional<double>, 3> value;  ///< prescribed components (null = free), times amplitude(t)
  Amplitude amplitude;
  /// Shell bodies: the region's boundary edges are clamped (their ghost
  /// vertices even: zero slope across the edge; docs/shells.md), besides held.
  bool clamped = false;
  std::string key;
  /// "velocity" or "displacement": the key of the values.
  const char* quantity() const { return displacement ? "displacement" : "velocity"; }
  const char* unit() const { return displacement ? "m" : "m/s"; }
};

/// A surface load (loads[i]): a follower pressure or a dead traction on the
/// boundary faces of a region, times amplitude(t) (kernels/surface_load.hpp).
struct LoadSpec {
  int body = 0;
  RegionSpec region;
  std::optional<double> pressure;  ///< Pa, positive pushing into the body
  std::optional<Vec3> traction;    ///< Pa (N per m^2 of reference area), global frame
  Amplitude amplitude;
  std::string key;
};

struct ContactSpec {
  double friction = 0.0;     ///< Coulomb mu
  double restitution = 1.0;  ///< e in [0, 1]
  int max_sweeps = 100;       ///< cap on DCR Gauss-Seidel sweeps per step (contact.max_sweeps)
  double search_margin = 0.1; ///< candidate reuse margin, fraction of the median surface edge (contact.search_margin)
  DcrPlacement placement = DcrPlacement::End;  ///< contact.placement: end, middle or impact
  bool sweep_cap_fatal = false;  ///< contact.on_sweep_cap: fail (the run stops, exit 1) instead of warn
  /// contact.pairs: the body pairs (indices, a <= b; a == b: a body's self-contact) that may
  /// touch, ascending; empty: every pair, self-contact included.
  std::vector<std::array<int, 2>> pairs;
  /// contact.self: false drops every pair of one body (self-contact, between its own
  /// fragments too).
  bool self = true;
};

struct CheckpointSpec {
  long every_steps = 0;
  double every_seconds = 0;
};

struct Scene {
  std::string file;  ///< path of the scene file
  std::string name;
  double end_time = 0;
  std::optional<double> fixed_dt;
  double safety = 0.5;
  long fracture_check_every = 1;  ///< steps between facet checks (time.fracture_check_every)
  long output_every = -1;  ///< steps between field outputs; -1 = default (about 20 frames)
  long history_every = 1;
  std::vector<MaterialSpec> materials;
  std::vector<BodySpec> bodies;
  std::vector<BoundaryConditionSpec> boundary_conditions;
  std::vector<LoadSpec> loads;
  std::optional<ContactSpec> contact;
  Vec3 gravity = Vec3::Zero();
  std::optional<CheckpointSpec> checkpoint;

  bool has_shells() const {
    for (const auto& b : bodies)
      if (b.shell) return true;
    return false;
  }
  bool fracture_enabled() const {
    for (const auto& m : materials)
      if (m.fracture) return true;
    return false;
  }
};

/// The largest scene file read, bytes (1 MiB: a scene names shapes, files and
/// numbers, a few kB; yaml-cpp needs ~100 times the text in memory and ~0.7 s
/// per MiB, so a 50 MB file took 40 s and 5.8 GB only to be refused).
/// load_scene and parse_scene refuse a larger one before parsing it.
inline constexpr std::size_t kMaxSceneBytes = std::size_t{1} << 20;

/// The largest dilatational wave speed of a material, m/s (the speed of
/// light; diamond's is 1.8e4): a material beyond it is refused, since its
/// stable step would be 0 or too small to ever reach time.end.
inline constexpr double kMaxWaveSpeed = 3e8;

/// Load and check a scene. `overrides` are "key.path=value" strings (the
/// CLI's --set), applied to the YAML tree before checking; value is YAML.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

/// The same from the scene's text; `path` names the file in messages and
/// resolves relative mesh files (tests/fuzz/fuzz_scene.cpp feeds it any bytes:
/// every problem must be an InputError).
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

}  // namespace shatter
