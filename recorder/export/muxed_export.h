// An export into one Matroska or MP4 file, through GStreamer's own muxers:
// the frames as they were recorded, the telemetry lines as the "telemetry"
// text track (named and not shown by default, as in the recordings).
// Streamed, the muxer's bytes go out through an appsink as they come, the
// header held until the track is marked in it.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "export/byte_stream.h"
#include "export/export_sink.h"

namespace wircam::recorder {

class MuxedExport : public ExportSink {
 public:
  // `container`: "mkv" or "mp4".
  MuxedExport(ExportTarget target, std::string container);
  ~MuxedExport() override;

  std::optional<std::string> start(GstCaps* caps) override;
  std::optional<std::string> frame(GstBuffer* buffer, int64_t ptsNs, int64_t utcNs,
                                   bool key) override;
  std::optional<std::string> line(const nlohmann::json& line, int64_t ptsNs,
                                  int64_t utcNs) override;
  std::optional<std::string> finish() override;
  uint64_t bytesWritten() override;

 private:
  // An error the pipeline posted or the stream met, if any (without waiting).
  std::optional<std::string> failure();
  static GstPadProbeReturn onText(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  // Streamed: the muxer's bytes out, its header marked first.
  static GstFlowReturn onBytes(GstElement* appsink, gpointer self);
  bool send(const uint8_t* data, size_t size);
  bool sendHeader();
  // Waits while the muxer is this far behind (a slow reader), unless it failed.
  std::optional<std::string> waitForRoom();

  bool mkv() const { return container_ == "mkv"; }

  ExportTarget target_;
  std::string container_;
  GstElement* pipeline_ = nullptr;
  GstElement* out_ = nullptr;  // the filesink or the appsink
  std::unique_ptr<ByteStream> stream_;
  std::mutex streamLock_;  // the muxer's thread writes, the export's reads its count
  std::vector<uint8_t> header_;
  bool headerSent_ = false;
  GstElement* video_ = nullptr;  // the appsrcs
  GstElement* text_ = nullptr;
  int64_t textPts_ = -1;  // the newest text buffer's time
  // Each frame waits for the next, which gives it its duration: the last
  // one's is the interval before it (MP4 readers drop a frame that has none).
  std::optional<std::string> pushPending(int64_t durationNs);
  GstBuffer* pending_ = nullptr;
  int64_t pendingPts_ = 0, lastDuration_ = GST_SECOND / 15;
};

}  // namespace wircam::recorder
