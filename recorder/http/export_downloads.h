// GET /api/export?camera=NAME&start=ISO8601&end=ISO8601&format=mkv|mp4|mcap:
// a time range of one camera exported as wirc-export does, on a thread of
// its own, and streamed to the client as it is made (chunked; Matroska
// without its index, MP4 fragmented): the first bytes leave with the first
// frames, nothing is kept on disk, and the export goes no faster than the
// client takes it (a socket pair between them, read a block at a time when
// the last one is written), so the recorder's memory stays flat whatever
// the range. A client that leaves stops the export (its socket is looked at
// twice a second until the first bytes: libsoup does not read a request's
// connection while it waits for the answer). Main loop only.
#pragma once

#include <libsoup/soup.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

namespace wircam::recorder {

class ExportDownloads {
 public:
  // Exports running or being sent at once; more get a 503.
  static constexpr size_t kMaxAtOnce = 2;
  // A request's connection, for seeing whether its client is still there
  // (null when it is not known).
  using SocketOf = std::function<GSocket*(SoupServerMessage*)>;
  // Removes what an earlier version left in `recordings`/.exports.
  ExportDownloads(std::filesystem::path recordings, SocketOf socketOf);
  ~ExportDownloads();  // stops the exports
  ExportDownloads(const ExportDownloads&) = delete;
  ExportDownloads& operator=(const ExportDownloads&) = delete;

  // Answers at once with 400/404/503 JSON, or later with the file.
  void serve(SoupServerMessage* message, GHashTable* query);

 private:
  struct Download;
  static gboolean checkClient(gpointer download);
  void forget(Download* download);

  std::filesystem::path recordings_;
  SocketOf socketOf_;
  std::vector<std::unique_ptr<Download>> downloads_;
};

}  // namespace wircam::recorder
