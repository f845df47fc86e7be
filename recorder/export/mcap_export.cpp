#include "export/mcap_export.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "foxglove/foxglove_channels.h"
#include "foxglove/foxglove_messages.h"
#include "gst_scoped.h"

namespace wircam::recorder {

McapExport::McapExport(ExportTarget target, std::string stream)
    : target_(std::move(target)), stream_(std::move(stream)) {
  if (target_.stream >= 0) output_ = std::make_unique<ByteStream>(target_.stream);
}

std::optional<std::string> McapExport::start(GstCaps* caps) {
  std::string media = gst_structure_get_name(gst_caps_get_structure(caps, 0));
  format_ = media == "video/x-h264" ? "h264" : "jpeg";
  if (format_ == "h264") {
    // Foxglove decodes Annex B; the recordings hold "avc".
    const GValue* record = gst_structure_get_value(gst_caps_get_structure(caps, 0), "codec_data");
    if (record && GST_VALUE_HOLDS_BUFFER(record)) {
      gst::ScopedBufferMap map(gst_value_get_buffer(record), GST_MAP_READ);
      if (map) annexB_ = AnnexB::fromAvcC(map.view());
      if (!annexB_) return "the H.264 stream's codec_data is not an avcC record";
    }
  }
  if (output_) {
    FILE* file = output_->openFile();
    if (!file) return "cannot stream " + target_.path + ": " + std::strerror(errno);
    writer_ = McapWriter::create(file);
  } else {
    auto writer = McapWriter::create(target_.path);
    if (!writer) return writer.error();
    writer_ = std::move(*writer);
  }
  for (const auto& channel : foxgloveChannels({.video = format_ == "h264"})) {
    uint16_t schema =
        writer_->addSchema(channel.schemaName, channel.schemaEncoding, channel.schema);
    uint16_t id = writer_->addChannel(schema, foxgloveTopicName(stream_, channel), channel.encoding,
                                      channel.compressible);
    switch (channel.topic) {
      case FoxgloveTopic::Image:
        image_ = id;
        break;
      case FoxgloveTopic::Tags:
        tags_ = id;
        break;
      case FoxgloveTopic::Telemetry:
        telemetry_ = id;
        break;
      case FoxgloveTopic::Log:
        log_ = id;
        break;
      case FoxgloveTopic::Pose:
        break;
    }
  }
  return std::nullopt;
}

std::optional<std::string> McapExport::frame(GstBuffer* buffer, int64_t, int64_t utcNs, bool) {
  if (output_ && !output_->error().empty()) return output_->error();  // the reader is gone
  gst::ScopedBufferMap map(buffer, GST_MAP_READ);
  if (!map) return "an unreadable frame";
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  if (annexB_) {
    auto frame = annexB_->convert(map.view());
    if (!frame) return "an H.264 frame whose NAL lengths run past its end";
    writer_->write(image_, time, time, compressedVideoHead(utcNs, stream_, format_, frame->size()),
                   *frame);
    return std::nullopt;
  }
  // The message's fields, then the frame's bytes as they are.
  writer_->write(image_, time, time, compressedImageHead(utcNs, stream_, format_, map.size()),
                 {reinterpret_cast<const char*>(map.data()), map.size()});
  return std::nullopt;
}

std::optional<std::string> McapExport::line(const nlohmann::json& line, int64_t, int64_t utcNs) {
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  write(telemetry_, utcNs, line);
  std::string type = line.value("type", "");
  if (type == "detections") writer_->write(tags_, time, time, imageAnnotationsOf(line, utcNs));
  // Events, not the vehicle's status reports (twice a second: telemetry).
  bool vehicleEvent = type == "vehicle" && line.contains("event") && line["event"] != "status";
  if (type == "session" || vehicleEvent) {
    std::string message = line.value("event", type);
    write(log_, utcNs, foxgloveLog(stream_, message, utcNs));
  }
  return std::nullopt;
}

std::optional<std::string> McapExport::finish() {
  bool written = writer_->finish();
  if (output_ && !output_->error().empty()) return output_->error();
  if (!written) return "cannot write " + target_.path + ": " + std::strerror(errno);
  return std::nullopt;
}

void McapExport::write(uint16_t channel, int64_t utcNs, const nlohmann::json& message) {
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  writer_->write(channel, time, time, message.dump());
}

}  // namespace wircam::recorder
