#include "runtime/patch_ranks.hpp"

#include <algorithm>
#include <bit>

#include "kernels/error.hpp"
#include "runtime/contact_patch.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/timed.hpp"

namespace shatter {

namespace {

constexpr int kLink = 1, kLinkAnswer = 2, kPost = 3, kSettle = 4, kSettleOn = 5;
constexpr size_t kLinkWords = 8, kAnswerWords = 3, kStateWords = 7;

std::uint64_t word(double x) { return std::bit_cast<std::uint64_t>(x); }
double real(std::uint64_t w) { return std::bit_cast<double>(w); }
std::uint64_t word(int r) { return static_cast<std::uint64_t>(r + 1); }
int rank_of(std::uint64_t w) { return static_cast<int>(w) - 1; }

}  // namespace

PatchRanks::PatchRanks(const ContactPatch& patch, const Decomposition& dec) : patch_(patch), rank_(dec.rank()) {
  MPI_Comm_dup(dec.comm(), &comm_);
}

PatchRanks::~PatchRanks() {
  if (!requests_.empty()) MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  if (comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

std::uint64_t PatchRanks::id(Index node) const { return static_cast<std::uint64_t>(patch_.whole(node)); }

long PatchRanks::total(long count) {
  timed(seconds_, cpu_seconds_, [&] { MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_LONG, MPI_SUM, comm_); });
  return count;
}

size_t PatchRanks::neighbor(int r) const {
  const std::span<const int> n = patch_.neighbors();
  const auto it = std::lower_bound(n.begin(), n.end(), r);
  SHATTER_ASSERT(it != n.end() && *it == r);
  return static_cast<size_t>(it - n.begin());
}

std::vector<PatchRanks::Words> PatchRanks::exchange(const std::vector<Words>& out, int tag) {
  const std::span<const int> n = patch_.neighbors();
  std::vector<MPI_Request> sends(n.size());
  for (size_t k = 0; k < n.size(); ++k) {
    MPI_Isend(out[k].data(), static_cast<int>(out[k].size()), MPI_UINT64_T, n[k], tag, comm_, &sends[k]);
    bytes_ += static_cast<long>(sizeof(std::uint64_t) * out[k].size());
  }
  std::vector<Words> in(n.size());
  for (size_t k = 0; k < n.size(); ++k) {
    MPI_Status status;
    MPI_Probe(n[k], tag, comm_, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_UINT64_T, &count);
    in[k].resize(count);
    MPI_Recv(in[k].data(), count, MPI_UINT64_T, n[k], tag, comm_, MPI_STATUS_IGNORE);
  }
  MPI_Waitall(static_cast<int>(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
  return in;
}

void PatchRanks::link(std::vector<DcrLink>& links) {
  return timed(seconds_, cpu_seconds_, [&] {
    // To the volume owner of each link's node: its whole id, its pair's key, its tag.
    const std::span<const int> neighbors = patch_.neighbors();
    std::vector<Words> out(neighbors.size());
    std::vector<DcrLink> home;  // the links of the nodes owned here, from every rank
    for (size_t k = 0; k < links.size(); ++k) {
      const auto n = static_cast<Index>(links[k].node);
      const std::uint64_t whole = id(n);
      const int owner = patch_.owner(n);
      if (owner == rank_) {
        home.push_back({whole, links[k].key, rank_, k});
        continue;
      }
      const DcrKey& key = links[k].key;
      Words& w = out[neighbor(owner)];
      w.insert(w.end(), {whole, key.hash, key.kind, key.ids[0], key.ids[1], key.ids[2], key.ids[3], k});
    }
    const std::vector<Words> asked = exchange(out, kLink);
    for (size_t r = 0; r < asked.size(); ++r)
      for (size_t at = 0; at < asked[r].size(); at += kLinkWords) {
        const std::uint64_t* w = &asked[r][at];
        const DcrKey key{w[1], static_cast<ContactPair::Kind>(w[2]), {w[3], w[4], w[5], w[6]}};
        home.push_back({w[0], key, neighbors[r], w[7]});
      }
    order_links(home);
    for (Words& w : out) w.clear();
    for (const DcrLink& h : home) {
      if (h.rank == rank_) {
        links[h.tag].pred = h.pred;
        links[h.tag].succ = h.succ;
      } else {
        Words& w = out[neighbor(h.rank)];
        w.insert(w.end(), {h.tag, word(h.pred), word(h.succ)});
      }
    }
    for (const Words& answers : exchange(out, kLinkAnswer))
      for (size_t at = 0; at < answers.size(); at += kAnswerWords) {
        DcrLink& l = links[answers[at]];
        l.pred = rank_of(answers[at + 1]);
        l.succ = rank_of(answers[at + 2]);
      }
  });
}

void PatchRanks::append(Words& w, Index node, const Vec3& x_new, const Vec3& v) const {
  w.insert(w.end(), {id(node), word(x_new.x()), word(x_new.y()),
                     word(x_new.z()), word(v.x()), word(v.y()), word(v.z())});
}

void PatchRanks::post(int r, std::span<const DcrNodeState> states) {
  return timed(seconds_, cpu_seconds_, [&] {
    Words& w = sending_.emplace_back();
    for (const DcrNodeState& s : states) {
      append(w, s.node, s.x_new, s.v);
      w.push_back(s.moved);
    }
    requests_.emplace_back();
    MPI_Isend(w.data(), static_cast<int>(w.size()), MPI_UINT64_T, r, kPost, comm_, &requests_.back());
    bytes_ += static_cast<long>(sizeof(std::uint64_t) * w.size());
    posted_ += static_cast<long>(states.size());
  });
}

std::vector<DcrNodeState> PatchRanks::receive(bool wait) {
  return timed(seconds_, cpu_seconds_, [&] {
    std::vector<DcrNodeState> states;
    while (true) {
      MPI_Status status;
      int flag = 0;
      if (wait && states.empty()) {
        MPI_Probe(MPI_ANY_SOURCE, kPost, comm_, &status);
        flag = 1;
      } else {
        MPI_Iprobe(MPI_ANY_SOURCE, kPost, comm_, &flag, &status);
      }
      if (!flag) return states;
      int count = 0;
      MPI_Get_count(&status, MPI_UINT64_T, &count);
      Words w(count);
      MPI_Recv(w.data(), count, MPI_UINT64_T, status.MPI_SOURCE, kPost, comm_, MPI_STATUS_IGNORE);
      for (size_t at = 0; at < w.size(); at += kStateWords + 1)
        states.push_back({patch_.node(static_cast<Index>(w[at])),
                          Vec3(real(w[at + 1]), real(w[at + 2]), real(w[at + 3])),
                          Vec3(real(w[at + 4]), real(w[at + 5]), real(w[at + 6])), w[at + 7] != 0});
    }
  });
}

std::vector<Index> PatchRanks::settle(std::span<const Index> last, std::span<Vec3> x_new, std::span<Vec3> v) {
  return timed(seconds_, cpu_seconds_, [&] {
    if (!requests_.empty()) MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
    requests_.clear();
    sending_.clear();
    const std::span<const int> neighbors = patch_.neighbors();
    // The final states to the volume owners ...
    std::vector<Words> out(neighbors.size());
    std::vector<std::pair<Index, int>> settled;  // (node owned here, the rank that resolved its last pair)
    for (const Index n : last) {
      const int owner = patch_.owner(n);
      if (owner == rank_) settled.emplace_back(n, rank_);
      else append(out[neighbor(owner)], n, x_new[n], v[n]);
    }
    std::vector<Index> written;
    auto write = [&](const std::vector<Words>& in, bool owned) {
      for (size_t r = 0; r < in.size(); ++r)
        for (size_t at = 0; at < in[r].size(); at += kStateWords) {
          const Index n = patch_.node(static_cast<Index>(in[r][at]));
          x_new[n] = Vec3(real(in[r][at + 1]), real(in[r][at + 2]), real(in[r][at + 3]));
          v[n] = Vec3(real(in[r][at + 4]), real(in[r][at + 5]), real(in[r][at + 6]));
          written.push_back(n);
          if (owned) settled.emplace_back(n, neighbors[r]);
        }
    };
    write(exchange(out, kSettle), true);
    // ... which send them on to the other ranks that read them.
    for (Words& w : out) w.clear();
    for (const auto& [n, from] : settled)
      for (const int r : patch_.readers(n))
        if (r != from) append(out[neighbor(r)], n, x_new[n], v[n]);
    write(exchange(out, kSettleOn), false);
    return written;
  });
}

}  // namespace shatter
