// Early-return helpers for absl::Status / absl::StatusOr, in the style of TensorStore.
#ifndef SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_
#define SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define SG_STATUS_CONCAT_INNER_(a, b) a##b
#define SG_STATUS_CONCAT_(a, b) SG_STATUS_CONCAT_INNER_(a, b)

// Returns from the enclosing function when `expr` (an absl::Status) is not OK.
#define SG_RETURN_IF_ERROR(expr)                                \
  do {                                                          \
    if (::absl::Status sg_status_ = (expr); !sg_status_.ok()) { \
      return sg_status_;                                        \
    }                                                           \
  } while (0)

// `lhs = value of expr` (an absl::StatusOr<T>), or returns its error status.
#define SG_ASSIGN_OR_RETURN(lhs, expr) \
  SG_ASSIGN_OR_RETURN_IMPL_(SG_STATUS_CONCAT_(sg_statusor_, __LINE__), lhs, expr)
#define SG_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                              \
  if (!tmp.ok()) return std::move(tmp).status();  \
  lhs = std::move(tmp).value()

#endif  // SPLINEGRID_CORE_UTIL_STATUS_MACROS_H_
