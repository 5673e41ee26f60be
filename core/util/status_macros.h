// Early-return helpers for absl::Status / absl::StatusOr, in the style of TensorStore.
//
// Both take an optional annotation: the remaining arguments, joined with absl::StrCat, are put
// in front of the message of an error that is returned (same code, payloads kept), e.g.
//   SG_RETURN_IF_ERROR(WriteVts(path, block, arrays), "block ", b, ": ");
//   SG_ASSIGN_OR_RETURN(Extents e, SampleExtents(distribution, level), "block ", b, ": ");
// The annotation is only built on the error path.
#ifndef SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_
#define SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"

namespace splinegrid::status_internal {

inline absl::Status Annotated(absl::Status status) { return status; }

// `status` with `prefix` in front of its message; the code and payloads stay.
inline absl::Status Annotated(const absl::Status& status, const std::string& prefix) {
  absl::Status out(status.code(), absl::StrCat(prefix, status.message()));
  status.ForEachPayload([&](absl::string_view type_url, const absl::Cord& payload) {
    out.SetPayload(type_url, payload);
  });
  return out;
}

}  // namespace splinegrid::status_internal

#define SG_STATUS_CONCAT_INNER_(a, b) a##b
#define SG_STATUS_CONCAT_(a, b) SG_STATUS_CONCAT_INNER_(a, b)

// Returns from the enclosing function when `expr` (an absl::Status) is not OK; the optional
// further arguments annotate the returned error (see the file comment).
#define SG_RETURN_IF_ERROR(expr, ...)                                       \
  do {                                                                      \
    if (::absl::Status sg_status_ = (expr); !sg_status_.ok()) {             \
      return ::splinegrid::status_internal::Annotated(                      \
          std::move(sg_status_) __VA_OPT__(, ::absl::StrCat(__VA_ARGS__))); \
    }                                                                       \
  } while (0)

// `lhs = value of expr` (an absl::StatusOr<T>), or returns its error status, annotated by the
// optional further arguments.
#define SG_ASSIGN_OR_RETURN(lhs, expr, ...)                                 \
  SG_ASSIGN_OR_RETURN_IMPL_(SG_STATUS_CONCAT_(sg_statusor_, __LINE__), lhs, \
                            expr __VA_OPT__(, ) __VA_ARGS__)
#define SG_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr, ...)                      \
  auto tmp = (expr);                                                        \
  if (!tmp.ok()) {                                                          \
    return ::splinegrid::status_internal::Annotated(                        \
        std::move(tmp).status() __VA_OPT__(, ::absl::StrCat(__VA_ARGS__))); \
  }                                                                         \
  lhs = std::move(tmp).value()

#endif  // SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_
