// The .sgrid archives: `splinegrid export` (ExportGrid) and `splinegrid import` (ImportArchive).
#include <fstream>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/io/record_file.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

absl::Status Export(const Args& args) {
  const std::string out = absl::GetFlag(FLAGS_o);
  if (args.size() != 1 || out.empty()) return Usage("usage: splinegrid export NAME -o FILE.sgrid");
  const std::string name = client::GridName(args[0]);
  ProgressLine download("export");
  SG_ASSIGN_OR_RETURN(const client::ArchiveSummary summary,
                      Connect()->ExportGrid(name, out, download.callback()));
  download.Done();
  Print(absl::StrCat("exported ", name, " to ", out, ": ", summary.revisions, " revision(s), ",
                     summary.source_chunks, " source chunk(s), ", summary.bytes, " bytes\n"),
        summary.header);
  return absl::OkStatus();
}

namespace {

// Whether the file at `path` starts like a record file (an unreadable one: the import says why).
bool LooksLikeRecordFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;
  std::string start(kRecordFileMagic.size(), '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  return in.gcount() == static_cast<std::streamsize>(start.size()) && start == kRecordFileMagic;
}

}  // namespace

absl::Status Import(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid import FILE.sgrid [--name NEW]");
  const std::string& path = args[0];
  if (!LooksLikeRecordFile(path)) {
    return Usage(absl::StrCat(path, " is not a splinegrid archive (a record file written by ",
                              "`splinegrid export`); for a Plot3D grid use `splinegrid fit ", path,
                              "`"));
  }
  SG_ASSIGN_OR_RETURN(const std::string id, NameFlagId());
  ProgressLine upload("import");
  SG_ASSIGN_OR_RETURN(const v1::Grid grid, Connect()->ImportArchive(path, id, upload.callback()));
  upload.Done();
  Print(absl::StrCat("imported ", path, " as ", grid.name(), " (", grid.revisions_size(),
                     " revision(s))\n", FormatGrid(grid)),
        grid);
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
