// GET /api/export?camera=NAME&start=ISO8601&end=ISO8601&format=mkv|mp4|mcap:
// a time range of one camera exported as wirc-export does, on a thread of
// its own, into the recordings folder's .exports/ (out of retention's
// reach: it only looks at the folder's own files), then sent to the client
// a block at a time (never the whole file in memory) and deleted once the
// response ends, however it ends. A client that leaves while its file is
// being written stops the export (its socket is looked at twice a second:
// libsoup does not read a request's connection while it waits for the
// answer). Main loop only.
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
  // Removes what a previous run left in `recordings`/.exports.
  ExportDownloads(std::filesystem::path recordings, SocketOf socketOf);
  ~ExportDownloads();  // stops the exports, removes their files
  ExportDownloads(const ExportDownloads&) = delete;
  ExportDownloads& operator=(const ExportDownloads&) = delete;

  // Answers at once with 400/404/503 JSON, or later with the file.
  void serve(SoupServerMessage* message, GHashTable* query);

 private:
  struct Download;
  void exported(Download* download);
  static gboolean checkClient(gpointer download);
  void forget(Download* download);

  std::filesystem::path recordings_, scratch_;
  SocketOf socketOf_;
  uint64_t serial_ = 0;
  std::vector<std::unique_ptr<Download>> downloads_;
};

}  // namespace wircam::recorder
