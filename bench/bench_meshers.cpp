// Gmsh's 3D meshers side by side (issue 22, "Meshing at the headline size";
// docs/performance.md "Meshing"): a cylinder of radius 0.5 and length 0.1
// meshed at size H by Delaunay (Mesh.Algorithm3D 1) or HXT (10) on THREADS
// threads, REPEATS times in this process. Per meshing: the wall time, the
// tetrahedra, the smallest altitude over H (3 V / largest face area: the
// stable step follows it) and its 0.1 % quantile, and a hash of the node
// coordinates, which tells whether two meshings gave the same mesh.
//
//   bench_meshers delaunay|hxt THREADS H [REPEATS]
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using P = std::array<double, 3>;

P minus(const P& a, const P& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
P cross(const P& a, const P& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const P& a, const P& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_meshers delaunay|hxt THREADS H [REPEATS]\n");
    return 2;
  }
  const std::string algorithm = argv[1];
  const int threads = std::atoi(argv[2]), repeats = argc > 4 ? std::atoi(argv[4]) : 1;
  const double h = std::atof(argv[3]);
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  for (int r = 0; r < repeats; ++r) {
    gmsh::clear();
    gmsh::option::setNumber("General.NumThreads", threads);
    gmsh::option::setNumber("Mesh.MaxNumThreads3D", threads);
    gmsh::model::add("cylinder");
    gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, 0.1, 0.5);
    gmsh::model::occ::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeMin", h);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.Algorithm3D", algorithm == "hxt" ? 10 : 1);
    const auto t0 = std::chrono::steady_clock::now();
    gmsh::model::mesh::generate(3);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<std::size_t> tags;
    std::vector<double> x, parametric;
    gmsh::model::mesh::getNodes(tags, x, parametric);
    std::uint64_t hash = 1469598103934665603ULL;  // FNV-1a of the coordinates, in Gmsh's order
    for (std::size_t i = 0; i < x.size() * sizeof(double); ++i)
      hash = (hash ^ reinterpret_cast<const unsigned char*>(x.data())[i]) * 1099511628211ULL;
    std::vector<std::size_t> at(*std::max_element(tags.begin(), tags.end()) + 1);
    for (std::size_t i = 0; i < tags.size(); ++i) at[tags[i]] = i;
    auto point = [&](std::size_t tag) { return P{x[3 * at[tag]], x[3 * at[tag] + 1], x[3 * at[tag] + 2]}; };
    std::vector<std::size_t> elements, nodes;
    gmsh::model::mesh::getElementsByType(4, elements, nodes);  // 4-node tetrahedra
    std::vector<double> altitude;
    for (std::size_t e = 0; e < elements.size(); ++e) {
      P p[4];
      for (int a = 0; a < 4; ++a) p[a] = point(nodes[4 * e + a]);
      const double volume = std::abs(dot(cross(minus(p[1], p[0]), minus(p[2], p[0])), minus(p[3], p[0]))) / 6;
      double largest = 0;
      for (const auto& f : {std::array{0, 1, 2}, std::array{0, 1, 3}, std::array{0, 2, 3}, std::array{1, 2, 3}}) {
        const P n = cross(minus(p[f[1]], p[f[0]]), minus(p[f[2]], p[f[0]]));
        largest = std::max(largest, 0.5 * std::sqrt(dot(n, n)));
      }
      altitude.push_back(3 * volume / largest / h);
    }
    std::sort(altitude.begin(), altitude.end());
    std::printf("%s threads %d h %g run %d: %zu tets, %.2f s, smallest altitude / h %.4f (0.1 %% quantile %.4f), "
                "nodes hash %016llx\n",
                algorithm.c_str(), threads, h, r + 1, elements.size(), seconds, altitude.front(),
                altitude[altitude.size() / 1000], static_cast<unsigned long long>(hash));
  }
  gmsh::finalize();
}
