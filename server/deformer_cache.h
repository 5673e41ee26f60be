// Deformers kept between DeformGrid calls. Building one costs O(controls x boundary points) and
// the factored boundary fits, and a coupled simulation deforms the same reference revision with
// the same boundary every step, so the server keeps the most recently used few.
#ifndef SPLINEGRID_SERVER_DEFORMER_CACHE_H_
#define SPLINEGRID_SERVER_DEFORMER_CACHE_H_

#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "core/deform/deform_quality.h"
#include "core/deform/deformer.h"
#include "server/memory_budget.h"

namespace splinegrid::server {

// The prefix of every DeformerCache key of grid `id` (server/ops/deform.cc makes the keys).
inline std::string DeformerKeyPrefix(const std::string& id) { return id + "#"; }

// A kept deformer and the fold gates made for it, one per check level, made on first use: the
// reference at that level, its cells and wall angles are the same for every step.
class KeptDeformer {
 public:
  // Gates of more reference cells than this (about 8-24 MB) are made for each call, not kept.
  static constexpr int64_t kMaxKeptGateCells = int64_t{1} << 20;

  explicit KeptDeformer(Deformer deformer) : deformer_(std::move(deformer)) {}

  const Deformer& deformer() const { return deformer_; }

  // Whether the gate of `level` is kept.
  bool HasGate(int level) const;

  // The fold gate of `level` for the deformer's reference (DeformationGate::Create, built
  // without holding the lock and polling `cancel`). Its bytes are charged to `budget` for as
  // long as it is held (RESOURCE_EXHAUSTED when the budget refuses them); a gate within
  // kMaxKeptGateCells is kept, and so held, until the deformer goes.
  absl::StatusOr<std::shared_ptr<const DeformationGate>> Gate(int level, MemoryBudget& budget,
                                                              const CancelCheck& cancel = {}) const;

 private:
  const Deformer deformer_;
  mutable std::mutex mu_;
  mutable std::map<int, std::shared_ptr<const DeformationGate>> gates_;
};

class DeformerCache {
 public:
  explicit DeformerCache(int capacity = 16) : capacity_(capacity) {}

  // The deformer of `key`, made by `make` (outside the lock) when it is not kept; the least
  // recently used entry goes when more than `capacity` are kept.
  absl::StatusOr<std::shared_ptr<const KeptDeformer>> Get(
      const std::string& key, const std::function<absl::StatusOr<Deformer>()>& make);

  // Drops every entry whose key starts with `prefix` (a deleted grid's).
  void Forget(const std::string& prefix);

  // Whether an entry whose key starts with `prefix` is kept with its fold gate of `level` (for
  // the scheduler: a deform whose deformer and gate are kept is cheap work).
  bool HasReady(const std::string& prefix, int level);

 private:
  const int capacity_;
  std::mutex mu_;
  std::list<std::pair<std::string, std::shared_ptr<const KeptDeformer>>> entries_;  // newest first
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_DEFORMER_CACHE_H_
