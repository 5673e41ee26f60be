// Disjoint sets over 0 .. n-1 with path halving (R. E. Tarjan and J. van Leeuwen, "Worst-case
// analysis of set union algorithms", J. ACM 31(2), 1984). The smaller index of two joined sets
// becomes their representative, so the first element in index order owns its set.
#ifndef SPLINEGRID_CORE_UTIL_UNION_FIND_H_
#define SPLINEGRID_CORE_UTIL_UNION_FIND_H_

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace splinegrid {

class UnionFind {
 public:
  explicit UnionFind(int64_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }

  int64_t Find(int64_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Join(int64_t a, int64_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }
  int64_t size() const { return static_cast<int64_t>(parent_.size()); }

 private:
  std::vector<int64_t> parent_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_UTIL_UNION_FIND_H_
