// Included by the targets that parse protobuf messages: silences protobuf's log (invalid UTF-8
// in string fields is logged on every such input, which costs time and floods the output).
#ifndef SPLINEGRID_TESTS_FUZZ_FUZZ_PROTO_H_
#define SPLINEGRID_TESTS_FUZZ_FUZZ_PROTO_H_

#include "google/protobuf/stubs/logging.h"

namespace splinegrid::fuzz {

inline const bool kProtobufLogSilenced = (google::protobuf::SetLogHandler(nullptr), true);

}  // namespace splinegrid::fuzz

#endif  // SPLINEGRID_TESTS_FUZZ_FUZZ_PROTO_H_
