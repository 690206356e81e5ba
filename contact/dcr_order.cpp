#include "contact/dcr_order.hpp"

#include <algorithm>

namespace shatter {

namespace {

/// splitmix64's finalizer (Steele, Lea & Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014): a bijection of 64-bit words that mixes every bit.
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

DcrKey dcr_key(ContactPair::Kind kind, const std::array<std::uint64_t, 4>& ids, int round) {
  std::uint64_t h = mix((static_cast<std::uint64_t>(round) << 1 | kind) + 1);
  for (const std::uint64_t id : ids) h = mix(h ^ (id + 0x9e3779b97f4a7c15ULL));
  return {h, kind, ids};
}

void order_links(std::vector<DcrLink>& links) {
  std::sort(links.begin(), links.end(), [](const DcrLink& a, const DcrLink& b) {
    return a.node != b.node ? a.node < b.node : a.key < b.key;
  });
  for (size_t k = 0; k < links.size(); ++k) {
    const bool first = k == 0 || links[k - 1].node != links[k].node;
    const bool last = k + 1 == links.size() || links[k + 1].node != links[k].node;
    links[k].pred = first ? -1 : links[k - 1].rank;
    links[k].succ = last ? -1 : links[k + 1].rank;
  }
}

}  // namespace shatter
