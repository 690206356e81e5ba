#pragma once
// The physics of a resolved scene as text, one `key.path=value` line per key
// (defaults filled in, numbers with 17 significant digits), for a restart to
// compare with the scene of the run that wrote the checkpoint
// (docs/checkpoint.md, "Restarting"). Left out: the run's name (checked on
// its own), time.end (a restart may extend it), time.safety and time.dt
// (the step length, which a restart after a failure is told to shorten),
// output.*, checkpoint.*, and a mesh file's path (its mesh is in the model
// fingerprint, and the scene folder may move).
#include <string>

#include "runtime/scene.hpp"

namespace shatter {

/// "key.path=value\n" lines of the physics keys of `scene`, in a fixed order.
std::string physics_keys(const Scene& scene);

/// The first key whose line differs between two physics_keys() texts, with
/// both values: {key, value in a, value in b}; a key missing from one side
/// has the value "(none)". All three empty when the texts are equal.
struct KeyDifference {
  std::string key, a, b;
};
KeyDifference first_difference(const std::string& a, const std::string& b);

}  // namespace shatter
