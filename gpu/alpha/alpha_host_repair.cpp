#include "gpu/alpha/alpha_host_repair.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

#include "core/exact/order.hpp"
#include "core/exact/radius_compare.hpp"
#include "core/exact/radius_rational.hpp"
#include "core/exact/simplex_radius.hpp"
#include "core/exact/weighted_radius_rational.hpp"

namespace galpha::detail {
namespace {

/// A limit of exact comparisons shared by the threads of one host repair. Each thread reports its
/// comparisons in batches (one atomic add per kBatch), so the limit is passed by at most kBatch
/// comparisons a thread before every thread sees it.
class SharedComparisonBudget {
 public:
  static constexpr uint64_t kBatch = 256;
  explicit SharedComparisonBudget(uint64_t max_comparisons) : max_(max_comparisons) {}
  /// Adds `n` comparisons; false once the total passed the limit.
  bool Spend(uint64_t n) {
    if (max_ == kNoComparisonLimit) return true;
    const uint64_t total = spent_.fetch_add(n, std::memory_order_relaxed) + n;
    if (total > max_) exhausted_.store(true, std::memory_order_relaxed);
    return !exhausted();
  }
  bool exhausted() const { return exhausted_.load(std::memory_order_relaxed); }

 private:
  const uint64_t max_;
  std::atomic<uint64_t> spent_{0};
  std::atomic<bool> exhausted_{false};
};

/// Exact comparison of two spectrum entries by simplex id, counting the path it took. Once the
/// shared budget is spent it answers "equal" without comparing, so that the sorts and searches
/// using it finish in a linear pass; their result is then not used (the caller throws).
class ExactComparator {
 public:
  ExactComparator(const AlphaInput& in, SharedComparisonBudget* budget) : in_(in), budget_(budget) {}
  ~ExactComparator() { budget_->Spend(unreported_); }

  int operator()(uint32_t a, uint32_t b) {
    if (++unreported_ == SharedComparisonBudget::kBatch) {
      budget_->Spend(unreported_);
      unreported_ = 0;
    }
    if (budget_->exhausted()) return 0;
    Point2 pa[3], pb[3];
    double wa[3], wb[3];
    const int na = Points(a, pa, wa), nb = Points(b, pb, wb);
    const Order c = CompareSimplexRadiusSqBounded(pa, Weights(wa), na, pb, Weights(wb), nb);
    if (c != Order::kUndecided) {
      ++counts_.bounded_exact;
      return SignOf(c);
    }
    ++counts_.cpu_fallback;
    return CompareSimplexRadiusSqRational(pa, Weights(wa), na, pb, Weights(wb), nb);
  }

  /// The simplex's points, and its weights into w when the family is weighted.
  int Points(uint32_t id, Point2* p, double* w) const {
    if (id < in_.num_triangles) {
      for (int k = 0; k < 3; ++k) {
        p[k] = in_.points[in_.triangles[id][k]];
        if (in_.weights != nullptr) w[k] = in_.weights[in_.triangles[id][k]];
      }
      return 3;
    }
    const std::array<uint32_t, 2>& e = in_.edges[id - in_.num_triangles];
    for (int k = 0; k < 2; ++k) {
      p[k] = in_.points[e[k]];
      if (in_.weights != nullptr) w[k] = in_.weights[e[k]];
    }
    return 2;
  }
  /// w for a weighted family, else nullptr (what the radius operations take).
  const double* Weights(const double* w) const { return in_.weights != nullptr ? w : nullptr; }

  const ComparisonCounts& counts() const { return counts_; }

 private:
  const AlphaInput& in_;
  SharedComparisonBudget* budget_;
  uint64_t unreported_ = 0;
  ComparisonCounts counts_;
};

/// Three-way quicksort (Dijkstra's partition): equal values gather around the pivot and are
/// never compared again, so exact ties cost one comparison each. Marks value starts.
void SortThreeWay(uint32_t* a, size_t n, uint8_t* new_value, ExactComparator& cmp) {
  while (n > 0) {
    if (n == 1) {
      new_value[0] = 1;
      return;
    }
    const uint32_t pivot = a[n / 2];
    size_t lt = 0, i = 0, gt = n;
    while (i < gt) {
      const int c = cmp(a[i], pivot);
      if (c < 0) {
        std::swap(a[lt++], a[i++]);
      } else if (c > 0) {
        std::swap(a[i], a[--gt]);
      } else {
        ++i;
      }
    }
    new_value[lt] = 1;
    for (size_t k = lt + 1; k < gt; ++k) new_value[k] = 0;
    // Recurse into the smaller side, loop on the larger (bounded stack depth).
    if (lt < n - gt) {
      SortThreeWay(a, lt, new_value, cmp);
      a += gt;
      new_value += gt;
      n -= gt;
    } else {
      SortThreeWay(a + gt, n - gt, new_value + gt, cmp);
      n = lt;
    }
  }
}

void Add(ComparisonCounts* total, const ComparisonCounts& part) {
  total->filter += part.filter;
  total->bounded_exact += part.bounded_exact;
  total->cpu_fallback += part.cpu_fallback;
}

}  // namespace

namespace {

/// Repairs a run whose every value is exactly a double (ExactDoubleRadiusSq: small integer
/// coordinates, grids): ordered and tied by those doubles alone. False, with nothing changed,
/// when some value is not.
bool RepairRunOfExactDoubles(ExactComparator& cmp, uint32_t* ids, uint32_t n, uint8_t* new_value,
                             ComparisonCounts* counts) {
  std::vector<std::pair<double, uint32_t>> values(n);
  for (uint32_t i = 0; i < n; ++i) {
    Point2 p[3];
    double w[3];
    const int k = cmp.Points(ids[i], p, w);
    if (!ExactDoubleSimplexRadiusSq(p, cmp.Weights(w), k, &values[i].first)) return false;
    values[i].second = ids[i];
  }
  // Congruent simplices (a grid's triangles) are all equal: one pass proves it.
  const bool all_equal =
      std::all_of(values.begin(), values.end(), [&](const auto& v) { return v.first == values[0].first; });
  if (!all_equal) std::sort(values.begin(), values.end());
  for (uint32_t i = 0; i < n; ++i) {
    ids[i] = values[i].second;
    new_value[i] = i == 0 || values[i].first != values[i - 1].first ? 1 : 0;
  }
  counts->bounded_exact += n - 1;
  return true;
}

}  // namespace

bool RepairRunsOnHost(const AlphaInput& in, const std::vector<std::array<uint32_t, 2>>& runs, uint64_t max_comparisons,
                      uint32_t* ids, uint8_t* new_value, ComparisonCounts* counts) {
  const long num_runs = static_cast<long>(runs.size());
  SharedComparisonBudget budget(max_comparisons);
#pragma omp parallel
  {
    ExactComparator cmp(in, &budget);
    ComparisonCounts shortcut;
#pragma omp for schedule(dynamic, 1)
    for (long r = 0; r < num_runs; ++r) {
      const uint32_t b = runs[r][0], e = runs[r][1];
      if (!RepairRunOfExactDoubles(cmp, ids + b, e - b, new_value + b, &shortcut)) {
        SortThreeWay(ids + b, e - b, new_value + b, cmp);
      }
    }
#pragma omp critical
    Add(counts, shortcut);
#pragma omp critical
    Add(counts, cmp.counts());
  }
  return !budget.exhausted();
}

bool MergeUncertifiedOnHost(const AlphaInput& in, std::vector<uint32_t> odd, uint64_t max_comparisons,
                            std::vector<uint32_t>* ids, std::vector<uint8_t>* new_value, ComparisonCounts* counts) {
  SharedComparisonBudget budget(max_comparisons);
  ExactComparator cmp(in, &budget);
  std::vector<uint8_t> odd_new(odd.size());
  SortThreeWay(odd.data(), odd.size(), odd_new.data(), cmp);
  // Value groups of the main order: starts of exact values.
  std::vector<uint32_t> starts;
  for (uint32_t i = 0; i < ids->size(); ++i) {
    if ((*new_value)[i]) starts.push_back(i);
  }
  std::vector<uint32_t> merged_ids;
  std::vector<uint8_t> merged_new;
  merged_ids.reserve(ids->size() + odd.size());
  merged_new.reserve(ids->size() + odd.size());
  size_t next_main = 0;  // next main entry to copy
  size_t lo_group = 0;   // groups before lo_group are below the current odd value
  for (size_t i = 0; i < odd.size(); ++i) {
    // First group whose value is >= odd[i] (exact binary search over group representatives).
    size_t lo = lo_group, hi = starts.size();
    int at = 1;
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      const int c = cmp((*ids)[starts[mid]], odd[i]);
      if (c < 0) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    if (lo < starts.size()) at = cmp((*ids)[starts[lo]], odd[i]);
    // Copy main entries of the groups below, and of an equal group (the odd entry joins it).
    const size_t copy_end = lo < starts.size()
                                ? (at == 0 ? (lo + 1 < starts.size() ? starts[lo + 1] : ids->size()) : starts[lo])
                                : ids->size();
    for (; next_main < copy_end; ++next_main) {
      merged_ids.push_back((*ids)[next_main]);
      merged_new.push_back((*new_value)[next_main]);
    }
    const bool joins_main = lo < starts.size() && at == 0;
    merged_ids.push_back(odd[i]);
    merged_new.push_back(joins_main ? 0 : odd_new[i]);
    lo_group = joins_main ? lo + 1 : lo;
  }
  for (; next_main < ids->size(); ++next_main) {
    merged_ids.push_back((*ids)[next_main]);
    merged_new.push_back((*new_value)[next_main]);
  }
  *ids = std::move(merged_ids);
  *new_value = std::move(merged_new);
  Add(counts, cmp.counts());
  return !budget.exhausted();
}

void NearestValuesOnHost(const AlphaInput& in, const std::vector<uint8_t>& needs, AlphaRanks* out) {
  SharedComparisonBudget unlimited(kNoComparisonLimit);  // it reads points; it compares nothing
  ExactComparator points(in, &unlimited);
  for (size_t r = 0; r < needs.size(); ++r) {
    if (!needs[r]) continue;
    Point2 p[3];
    double w[3];
    const int n = points.Points(out->spectrum_simplex[r], p, w);
    const std::optional<mpq_class> value = SimplexRadiusSqRational(p, points.Weights(w), n);
    out->spectrum[r] = value ? NearestDouble(*value) : HUGE_VAL;
  }
}

void ResolveAttachmentOnHost(const AlphaInput& in, const std::array<int32_t, 2>* edge_triangles,
                             const std::vector<uint32_t>& edge_ids, std::vector<uint8_t>* attached) {
  attached->assign(edge_ids.size(), 0);
  for (size_t i = 0; i < edge_ids.size(); ++i) {
    const std::array<uint32_t, 2>& e = in.edges[edge_ids[i]];
    for (const int32_t t : edge_triangles[edge_ids[i]]) {
      if (t < 0) continue;
      uint32_t r = in.triangles[t][0];
      for (const uint32_t v : in.triangles[t]) {
        if (!(in.points[v] == in.points[e[0]]) && !(in.points[v] == in.points[e[1]])) r = v;
      }
      if (WeightedAttachedSignRational(in.points[e[0]], in.points[e[1]], in.points[r], in.weights[e[0]],
                                       in.weights[e[1]], in.weights[r]) > 0) {
        (*attached)[i] = 1;
      }
    }
  }
}

}  // namespace galpha::detail
