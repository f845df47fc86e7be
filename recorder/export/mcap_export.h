// An export into MCAP for robotics viewers (Foxglove, Lichtblick), on the
// channels of foxglove/foxglove_channels.h (image, tags, telemetry: every
// sidecar line as it is, log: the session's events), as the live Foxglove
// WebSocket serves them.
// Images and tags are protobuf, with Foxglove's own schemas (their
// FileDescriptorSet in the Schema records): a frame's bytes go into the file
// as they are, at the speed of a copy. Telemetry and logs are JSON with JSON
// schemas, readable by any JSON tool, in chunks zstd compresses.
#pragma once

#include <memory>
#include <string>

#include "export/byte_stream.h"
#include "export/export_sink.h"
#include "export/mcap_writer.h"
#include "foxglove/annex_b.h"

namespace wircam::recorder {

class McapExport : public ExportSink {
 public:
  // `stream`: the camera's name, the topics' prefix.
  McapExport(ExportTarget target, std::string stream);

  std::optional<std::string> start(GstCaps* caps) override;
  std::optional<std::string> frame(GstBuffer* buffer, int64_t ptsNs, int64_t utcNs,
                                   bool key) override;
  std::optional<std::string> line(const nlohmann::json& line, int64_t ptsNs,
                                  int64_t utcNs) override;
  std::optional<std::string> finish() override;
  uint64_t bytesWritten() override { return writer_ ? writer_->bytesWritten() : 0; }

 private:
  void write(uint16_t channel, int64_t utcNs, const nlohmann::json& message);

  ExportTarget target_;
  std::unique_ptr<ByteStream> output_;  // streamed: where the writer's FILE* goes
  std::string stream_, format_;
  std::unique_ptr<McapWriter> writer_;
  std::optional<AnnexB> annexB_;  // for H.264: Foxglove decodes Annex B
  uint16_t image_ = 0, tags_ = 0, telemetry_ = 0, log_ = 0;
};

}  // namespace wircam::recorder
