#pragma once
// Two tiers of checks (STYLE.md "Errors"):
//  SHATTER_ASSERT(cond)            debug only, free in hot loops;
//  SHATTER_REQUIRE(cond, a << b)   always checked, throws shatter::Error.
// Input problems throw shatter::InputError (the CLI maps it to exit 2);
// everything else that goes wrong during a run is shatter::Error (exit 1).
#include <cassert>
#include <sstream>
#include <stdexcept>
#include <string>

namespace shatter {

/// A failure during a run (NaN, inverted element, exceeded cap): exit 1.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A failure during a run whose cause is the scene's physics (a collapsed
/// stable step, an energy overflow): a smaller time step does not cure it,
/// and a restart cannot change the physics. Exit 1.
class PhysicsError : public Error {
 public:
  using Error::Error;
};

/// Bad input (scene, mesh, command line): exit 2. The message names the file,
/// the key path and what was expected.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace shatter

#define SHATTER_ASSERT(cond) assert(cond)

#define SHATTER_REQUIRE(cond, msg)                      \
  do {                                                  \
    if (!(cond)) {                                      \
      std::ostringstream shatter_require_os_;           \
      shatter_require_os_ << msg;                       \
      throw ::shatter::Error(shatter_require_os_.str()); \
    }                                                   \
  } while (0)
