// Open streaming calls per principal (WatchGrid, EvaluateGrid, ImportGrid, ExportGrid,
// ImportArchive): each holds a StreamSlot from admission until it finishes (released just
// before the status is sent, so a client that has seen the status may open the next stream at
// once; the reactor's destruction releases it too), and a principal that already holds
// `max_per_principal` gets RESOURCE_EXHAUSTED naming the limit. Without it one client could
// open hundreds of watches (issue 12: 300 WatchGrid streams were accepted).
#ifndef SPLINEGRID_SERVER_STREAM_LIMITS_H_
#define SPLINEGRID_SERVER_STREAM_LIMITS_H_

#include <mutex>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"

namespace splinegrid::server {

class StreamLimits;

// One open stream of a principal; released when destroyed (or moved from). Movable only.
class StreamSlot {
 public:
  StreamSlot() = default;
  StreamSlot(StreamSlot&& other) noexcept;
  StreamSlot& operator=(StreamSlot&& other) noexcept;
  ~StreamSlot();

  // Releases the slot now (idempotent).
  void Release();

 private:
  friend class StreamLimits;
  StreamSlot(StreamLimits* limits, std::string principal)
      : limits_(limits), principal_(std::move(principal)) {}

  StreamLimits* limits_ = nullptr;
  std::string principal_;
};

class StreamLimits {
 public:
  // `max_per_principal` >= 1.
  explicit StreamLimits(int max_per_principal) : max_per_principal_(max_per_principal) {}

  // A slot of `principal`, or RESOURCE_EXHAUSTED naming the limit. The slot must not outlive
  // this object.
  absl::StatusOr<StreamSlot> Open(const std::string& principal);

  // Streams `principal` holds open now.
  int open(const std::string& principal) const;
  // Streams open now, all principals together (for the metrics endpoint).
  int open_total() const;

 private:
  friend class StreamSlot;
  void Close(const std::string& principal);

  const int max_per_principal_;
  mutable std::mutex mu_;
  absl::flat_hash_map<std::string, int> open_;  // principals with at least one open stream
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STREAM_LIMITS_H_
