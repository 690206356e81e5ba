// The ghost update (runtime/halo.hpp) on hand-made exchange lists, at any
// rank count (ctest runs it at 1, 2 and 3 ranks): every rank owns the global
// nodes g with g % ranks == rank and holds copies of some others, under its
// own local numbering. The copies it receives get their owners' values bit
// for bit (-0.0, subnormals, values near overflow), for any number of
// components, blocking or split; entries not in a receive list keep theirs;
// two Halos on one communicator never mix messages; stacked arrays send each
// node's chosen arrays; calls out of order or with arrays of the wrong size
// throw Error. Halo as the time loop uses it is tested through Decomposition
// (test_decomposition).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <vector>

#include "kernels/error.hpp"
#include "mesh/partition.hpp"
#include "mpi_environment.hpp"
#include "runtime/halo.hpp"

namespace shatter {
namespace {

constexpr Index kNodes = 60;  ///< global nodes; every rank has a slot for each

/// This rank's exchange lists when rank q holds a copy of node g owned by
/// another rank exactly when holds(g, q); local ids are a rank-dependent
/// rotation of the global ones.
struct Exchange {
  int rank = 0, size = 1;
  NodeExchange send, receive;
  std::vector<char> received;  ///< per local node: filled by the update

  static int owner(Index g, int size) { return static_cast<int>(g % size); }
  Index local(Index g) const { return (g + 7 * rank) % kNodes; }

  template <class Holds>
  explicit Exchange(Holds holds) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    std::map<int, std::vector<Index>> out, in;
    received.assign(kNodes, 0);
    for (Index g = 0; g < kNodes; ++g) {  // ascending g: both sides list a pair's nodes alike
      const int o = owner(g, size);
      for (int q = 0; q < size; ++q)
        if (o == rank && q != rank && holds(g, q)) out[q].push_back(local(g));
      if (o != rank && holds(g, rank)) {
        in[o].push_back(local(g));
        received[local(g)] = 1;
      }
    }
    send = exchange_from(out);
    receive = exchange_from(in);
  }
};

bool holds_quarter(Index g, int q) {
  return (g + q) % 4 != 0;
}
bool holds_third(Index g, int q) {
  return (g + 2 * q) % 3 == 1;
}

/// Component c of node g's owned value: a spread of bit patterns.
double owned_value(Index g, int c, double scale = 1.0) {
  switch (c % 4) {
    case 0:
      return g == 0 ? -0.0 : scale / (g + 3);
    case 1:
      return std::numeric_limits<double>::denorm_min() * static_cast<double>(g + 1) * scale;
    case 2:
      return -std::sqrt(g + 2.0) * 1e300 * scale;
    default:
      return std::nextafter(scale * static_cast<double>(g), 1e308);
  }
}
constexpr double kKept = -7.25;  ///< entries no update may touch

/// Owned values at owned nodes, NaN at received copies, kKept elsewhere.
std::vector<double> before_update(const Exchange& x, int components, double scale = 1.0) {
  std::vector<double> v(static_cast<size_t>(kNodes) * components, kKept);
  for (Index g = 0; g < kNodes; ++g)
    for (int c = 0; c < components; ++c) {
      double& entry = v[x.local(g) * components + c];
      if (Exchange::owner(g, x.size) == x.rank)
        entry = owned_value(g, c, scale);
      else if (x.received[x.local(g)])
        entry = std::nan("");
    }
  return v;
}

/// Local nodes whose entries differ in any bit from what the update must give.
long wrong_nodes(const Exchange& x, std::span<const double> v, int components, double scale = 1.0) {
  long wrong = 0;
  for (Index g = 0; g < kNodes; ++g) {
    const bool has_owned = Exchange::owner(g, x.size) == x.rank || x.received[x.local(g)];
    for (int c = 0; c < components; ++c) {
      const double want = has_owned ? owned_value(g, c, scale) : kKept;
      const double got = v[x.local(g) * components + c];
      if (std::memcmp(&got, &want, sizeof(double)) != 0) {
        ++wrong;
        break;
      }
    }
  }
  return wrong;
}

long received_over_ranks(const Exchange& x) {
  long mine = static_cast<long>(x.receive.nodes.size()), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

TEST(Halo, UpdateDeliversTheOwnersValuesBitForBit) {
  const Exchange x(holds_quarter);
  Halo halo(kNodes, x.send, x.receive, MPI_COMM_WORLD, kGhostTag);
  if (x.size > 1) {
    EXPECT_GT(received_over_ranks(x), 0) << "the lists exchange something";
  }
  for (int components : {1, 2, 4}) {
    std::vector<double> blocking = before_update(x, components), split = blocking;
    halo.update_ghosts(blocking, components);
    EXPECT_EQ(wrong_nodes(x, blocking, components), 0) << components << " components, update_ghosts";
    halo.begin_update(split, components);
    // Interior work between begin and end: the entries that are neither sent nor received.
    for (Index g = 0; g < kNodes; ++g)
      if (Exchange::owner(g, x.size) != x.rank && !x.received[x.local(g)])
        for (int c = 0; c < components; ++c) split[x.local(g) * components + c] = kKept;
    halo.end_update(split, components);
    EXPECT_EQ(wrong_nodes(x, split, components), 0) << components << " components, begin/end";
  }
  // Vec3 arrays are 3 node-major doubles per node.
  const std::vector<double> flat = before_update(x, 3);
  std::vector<Vec3> v(kNodes), w(kNodes);
  for (Index n = 0; n < kNodes; ++n) v[n] = w[n] = Vec3(flat[3 * n], flat[3 * n + 1], flat[3 * n + 2]);
  halo.update_ghosts(v);
  halo.begin_update(w);
  halo.end_update(w);
  EXPECT_EQ(wrong_nodes(x, {v.data()->data(), 3 * v.size()}, 3), 0) << "Vec3, update_ghosts";
  EXPECT_EQ(wrong_nodes(x, {w.data()->data(), 3 * w.size()}, 3), 0) << "Vec3, begin/end";

  // What one update sends: the listed nodes, one message per rank listed.
  long sent = 0;
  int messages = 0;
  for (int q = 0; q < x.size; ++q) {
    long to_q = 0;
    for (Index g = 0; g < kNodes; ++g)
      to_q += Exchange::owner(g, x.size) == x.rank && q != x.rank && holds_quarter(g, q);
    sent += to_q;
    messages += to_q > 0;
  }
  EXPECT_EQ(halo.update_bytes(3), static_cast<std::size_t>(sent) * 3 * sizeof(double));
  EXPECT_EQ(halo.update_messages(), messages);
}

// Two arrays stacked (update_stacked): every listed node's entry of the first, and the
// second's of some listed nodes only (both()), in one message per rank.
TEST(Halo, StackedArraysSendEachNodesChosenArrays) {
  const Exchange x(holds_quarter);
  const auto global = [&](Index local) { return (local - 7 * x.rank % kNodes + kNodes) % kNodes; };
  const auto both = [](Index g) { return (g / 3) % 2 == 0; };  // (not a function of the owner)
  const auto stacked = [&](const NodeExchange& lists) {
    NodeExchange out;
    for (int i = 0; i < lists.num_ranks(); ++i) {
      out.ranks.push_back(lists.ranks[i]);
      for (const Index n : lists.nodes_of(i)) out.nodes.push_back(n);
      for (const Index n : lists.nodes_of(i))
        if (both(global(n))) out.nodes.push_back(kNodes + n);
      out.offsets.push_back(static_cast<Index>(out.nodes.size()));
    }
    return out;
  };
  Halo halo(2 * kNodes, 2 * kNodes, stacked(x.send), stacked(x.receive), MPI_COMM_WORLD, kGhostTag);
  const auto value = [](Index g, double scale) {
    return Vec3(owned_value(g, 0, scale), owned_value(g, 1, scale), owned_value(g, 2, scale));
  };
  std::vector<Vec3> a(kNodes, Vec3::Constant(kKept)), b = a;
  for (Index g = 0; g < kNodes; ++g)
    if (Exchange::owner(g, x.size) == x.rank) a[x.local(g)] = value(g, 1.0), b[x.local(g)] = value(g, -3.0);
  const std::span<const Vec3> from[] = {a, b};
  std::vector<Vec3> to_a = a, to_b = b;
  const std::span<Vec3> to[] = {to_a, to_b};
  halo.update_stacked(from, to);
  long wrong = 0, second = 0;
  for (Index g = 0; g < kNodes; ++g) {
    const Index l = x.local(g);
    const bool owned = Exchange::owner(g, x.size) == x.rank, got = x.received[l];
    const Vec3 want_a = owned || got ? value(g, 1.0) : Vec3::Constant(kKept);
    const Vec3 want_b = owned || (got && both(g)) ? value(g, -3.0) : Vec3::Constant(kKept);
    wrong += std::memcmp(to_a[l].data(), want_a.data(), sizeof(Vec3)) != 0;
    wrong += std::memcmp(to_b[l].data(), want_b.data(), sizeof(Vec3)) != 0;
    second += got && both(g);
  }
  EXPECT_EQ(wrong, 0);
  if (x.size > 1) {
    EXPECT_GT(second, 0) << "some nodes receive both arrays";
    EXPECT_LT(second, static_cast<long>(x.receive.nodes.size())) << "and some the first only";
  }
  EXPECT_EQ(halo.update_bytes(3), stacked(x.send).nodes.size() * 3 * sizeof(double));
  // Stacks of the wrong total size throw.
  const std::span<const Vec3> short_from[] = {a};
  EXPECT_THROW(halo.update_stacked(short_from, to), Error);
}

TEST(Halo, TwoHalosOnOneCommunicatorDoNotMixMessages) {
  // Odd ranks post the second Halo's messages first; with one tag they
  // would be matched to the first's receives (HaloTag keeps them apart).
  const Exchange xa(holds_quarter), xb(holds_third);
  Halo a(kNodes, xa.send, xa.receive, MPI_COMM_WORLD, kGhostTag), b(kNodes, xb.send, xb.receive, MPI_COMM_WORLD, kPatchTag);
  std::vector<double> va = before_update(xa, 2), vb = before_update(xb, 2, -3.0);
  if (xa.rank % 2 == 0) {
    a.begin_update(va, 2);
    b.begin_update(vb, 2);
  } else {
    b.begin_update(vb, 2);
    a.begin_update(va, 2);
  }
  b.end_update(vb, 2);
  a.end_update(va, 2);
  EXPECT_EQ(wrong_nodes(xa, va, 2), 0);
  EXPECT_EQ(wrong_nodes(xb, vb, 2, -3.0), 0);
}

TEST(Halo, CallsOutOfOrderOrOfTheWrongSizeThrow) {
  const Exchange x(holds_quarter);
  Halo halo(kNodes, x.send, x.receive, MPI_COMM_WORLD, kGhostTag);
  std::vector<double> v = before_update(x, 3);
  EXPECT_THROW(halo.end_update(v, 3), Error) << "end without begin";
  EXPECT_THROW(halo.update_ghosts(std::span<double>(v).first(v.size() - 1), 3), Error) << "one double short";
  EXPECT_THROW(halo.update_ghosts(v, 2), Error) << "3 doubles per node read as 2";
  EXPECT_THROW(halo.update_ghosts(std::span<double>(), 0), Error) << "no components";
  halo.begin_update(v, 3);
  EXPECT_THROW(halo.begin_update(v, 3), Error) << "two begins without an end";
  EXPECT_THROW(halo.update_ghosts(v, 3), Error) << "a blocking update while one is pending";
  // The pending update is intact and completes.
  halo.end_update(v, 3);
  EXPECT_EQ(wrong_nodes(x, v, 3), 0);
  EXPECT_THROW(halo.end_update(v, 3), Error) << "two ends";
}

}  // namespace
}  // namespace shatter
