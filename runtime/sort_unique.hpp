#pragma once
// Sorts a list and drops its repeats: the id lists of the contact patch and
// of the decomposition's node lists.
#include <algorithm>
#include <vector>

namespace shatter {

template <class T>
void sort_unique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace shatter
