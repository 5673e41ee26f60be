// libFuzzer target: a sequence of ArchiveRecord messages -> GridAssembler
// (server/store/grid_archive.cc), which runs every archive converter of
// proto/convert/archive_*.cc: header and source chunks (SourceAssembler), connectivity, and
// revisions (blocks' splines, distributions, fit options and reports, boundary kinds,
// deformation checks). The input is records framed by a 4-byte little-endian length (the
// record file's framing without the CRC, so the fuzzer can change payloads; record_file.cc
// fuzzes the framing itself). Every input must assemble or give INVALID_ARGUMENT /
// RESOURCE_EXHAUSTED (32 MiB budget); an assembled grid must export and re-assemble, and every
// reservation must be released when the grid is gone.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "server/memory_budget.h"
#include "server/store/grid_archive.h"
#include "splinegrid/v1/archive.pb.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using splinegrid::server::GridAssembler;
using splinegrid::server::MemoryBudget;
using splinegrid::server::StoredGrid;

constexpr int64_t kBudgetBytes = int64_t{32} << 20;

void CheckAssemblyError(const absl::Status& status) {
  if (status.code() == absl::StatusCode::kResourceExhausted) return;
  splinegrid::fuzz::CheckRejection(status);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  MemoryBudget budget(kBudgetBytes);
  {
    GridAssembler assembler(&budget, /*id=*/"");
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    splinegrid::v1::ArchiveRecord record;
    while (rest.size() >= 4) {
      const uint32_t length = static_cast<uint32_t>(static_cast<uint8_t>(rest[0])) |
                              static_cast<uint32_t>(static_cast<uint8_t>(rest[1])) << 8 |
                              static_cast<uint32_t>(static_cast<uint8_t>(rest[2])) << 16 |
                              static_cast<uint32_t>(static_cast<uint8_t>(rest[3])) << 24;
      rest.remove_prefix(4);
      if (length > rest.size()) return 0;  // a torn record: the record reader's error
      if (!record.ParseFromArray(rest.data(), static_cast<int>(length))) return 0;
      rest.remove_prefix(length);
      const absl::Status added = assembler.Add(record);
      if (!added.ok()) {
        CheckAssemblyError(added);
        return 0;
      }
    }
    absl::StatusOr<std::shared_ptr<StoredGrid>> grid = assembler.Finish(/*check_counts=*/true);
    if (!grid.ok()) {
      CheckAssemblyError(grid.status());
      return 0;
    }
    // What was accepted must export and come back (as ExportGrid then ImportArchive would).
    MemoryBudget again_budget(kBudgetBytes);
    {
      GridAssembler again(&again_budget, /*id=*/"");
      const absl::Status exported = splinegrid::server::ForEachRecord(
          **grid, [&](const splinegrid::v1::ArchiveRecord& r) { return again.Add(r); });
      FUZZ_CHECK(exported.ok(), exported.ToString());
      absl::StatusOr<std::shared_ptr<StoredGrid>> reassembled = again.Finish(true);
      FUZZ_CHECK(reassembled.ok(), reassembled.status().ToString());
      FUZZ_CHECK((*reassembled)->revisions.size() == (*grid)->revisions.size(),
                 "revision count changed");
    }
    FUZZ_CHECK(again_budget.used() == 0, "re-assembly left memory reserved");
  }
  FUZZ_CHECK(budget.used() == 0, "assembly left memory reserved");
  return 0;
}
