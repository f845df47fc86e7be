// An export into one Matroska or MP4 file, through GStreamer's own muxers:
// the frames as they were recorded, the telemetry lines as the "telemetry"
// text track (named and not shown by default, as in the recordings).
#pragma once

#include <string>

#include "export/export_sink.h"

namespace wircam::recorder {

class MuxedExport : public ExportSink {
 public:
  // `container`: "mkv" or "mp4".
  MuxedExport(std::string path, std::string container);
  ~MuxedExport() override;

  std::optional<std::string> start(GstCaps* caps) override;
  std::optional<std::string> frame(GstBuffer* buffer, int64_t ptsNs, int64_t utcNs,
                                   bool key) override;
  std::optional<std::string> line(const nlohmann::json& line, int64_t ptsNs,
                                  int64_t utcNs) override;
  std::optional<std::string> finish() override;

 private:
  // An error the pipeline posted, if any (without waiting).
  std::optional<std::string> failure();
  static GstPadProbeReturn onText(GstPad* pad, GstPadProbeInfo* info, gpointer self);

  std::string path_, container_;
  GstElement* pipeline_ = nullptr;
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
