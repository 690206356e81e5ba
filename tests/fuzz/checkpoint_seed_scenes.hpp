#pragma once
// The two scenes of the checkpoint fuzz seeds (tests/fuzz/seeds/checkpoint/,
// tests/fuzz/README.md), without and with fracture: read by fuzz_checkpoint
// and by the tests that read the seeds.

namespace shatter::test {

// The seeds were written by `shatter run` from these two texts (tests/fuzz/README.md).
inline const char* const kCheckpointSeedScenes[] = {
    "name: fuzz_checkpoint\n"
    "time: {end: 1.0e-6}\n"
    "materials:\n"
    "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - name: b\n"
    "    material: steel\n"
    "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}\n"
    "    initial_velocity: [1, 0, 0]\n",
    "name: fuzz_checkpoint\n"
    "time: {end: 1.0e-6}\n"
    "materials:\n"
    "  glass: {model: neo_hookean, density: 2500, youngs_modulus: 70.0e9, poisson_ratio: 0.22,\n"
    "          fracture: {strength: 1.0e6, energy: 1.0}}\n"
    "bodies:\n"
    "  - name: b\n"
    "    material: glass\n"
    "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}\n"
    "    velocity_gradient: [[2000, 0, 0], [0, 0, 0], [0, 0, 0]]\n",
};

}  // namespace shatter::test
