#include "recording/playback_stream.h"

#include <cmath>

#include "recording/segment_reader.h"

namespace wircam::recorder {

PlaybackStream::PlaybackStream(Callbacks callbacks) : callbacks_(std::move(callbacks)) {}

Expected<std::unique_ptr<PlaybackStream>, PlaybackStream::Refusal> PlaybackStream::start(
    const std::string& path, double fromSeconds, Callbacks callbacks) {
  std::unique_ptr<PlaybackStream> self(new PlaybackStream(std::move(callbacks)));
  GError* error = nullptr;
  // The caps filter refuses a segment of another codec (H.264 plays in the
  // page's <video> element from the file itself).
  self->pipeline_ = gst_parse_launch(
      "filesrc name=file ! matroskademux ! image/jpeg ! appsink name=frames sync=true "
      "max-buffers=4 emit-signals=true",
      &error);
  if (!self->pipeline_) {
    std::string text = error ? error->message : "cannot build the replay pipeline";
    g_clear_error(&error);
    return unexpected(Refusal{false, text});
  }
  GstElement* file = gst_bin_get_by_name(GST_BIN(self->pipeline_), "file");
  g_object_set(file, "location", path.c_str(), nullptr);
  gst_object_unref(file);
  GstElement* frames = gst_bin_get_by_name(GST_BIN(self->pipeline_), "frames");
  g_signal_connect(frames, "new-sample", G_CALLBACK(onSample), self.get());
  gst_object_unref(frames);
  GstBus* bus = gst_element_get_bus(self->pipeline_);
  self->busWatch_ = gst_bus_add_watch(bus, onBusMessage, self.get());
  gst_object_unref(bus);

  // Paused first, so the seek lands before the first frame is shown.
  if (gst_element_set_state(self->pipeline_, GST_STATE_PAUSED) == GST_STATE_CHANGE_FAILURE ||
      gst_element_get_state(self->pipeline_, nullptr, nullptr, 5 * GST_SECOND) !=
          GST_STATE_CHANGE_SUCCESS)
    return unexpected(
        Refusal{false, "cannot read '" + path + "' as a Matroska file of JPEG frames"});
  // Past the end there is no frame to start at (and a position of 1e308 s
  // has no nanoseconds to seek to). A file still being written has no
  // duration yet: its seek finds what there is.
  gint64 duration = -1;
  bool known =
      gst_element_query_duration(self->pipeline_, GST_FORMAT_TIME, &duration) && duration > 0;
  double end = known ? static_cast<double>(duration) / GST_SECOND : 1e7;
  if (fromSeconds >= end) {
    char text[96];
    g_snprintf(text, sizeof text, "from=%.3g s is past the recording's end (%.1f s)", fromSeconds,
               end);
    return unexpected(Refusal{true, known ? text : "from= is past any recording's length"});
  }
  if (fromSeconds > 0 &&
      !gst_element_seek_simple(
          self->pipeline_, GST_FORMAT_TIME,
          // Accurate: from the frame at the offset, not the index point before it.
          static_cast<GstSeekFlags>(GST_SEEK_FLAG_FLUSH | GST_SEEK_FLAG_ACCURATE),
          static_cast<gint64>(std::llround(fromSeconds * GST_SECOND))))
    return unexpected(Refusal{false, "cannot seek to " + std::to_string(fromSeconds) + " s"});
  gst_element_set_state(self->pipeline_, GST_STATE_PLAYING);
  return self;
}

PlaybackStream::~PlaybackStream() {
  alive_.reset();
  if (busWatch_) g_source_remove(busWatch_);
  if (pipeline_) {
    gst_element_set_state(pipeline_, GST_STATE_NULL);
    gst_object_unref(pipeline_);
  }
}

GstFlowReturn PlaybackStream::onSample(GstElement* sink, gpointer data) {
  auto* self = static_cast<PlaybackStream*>(data);
  GstSample* sample = nullptr;
  g_signal_emit_by_name(sink, "pull-sample", &sample);
  if (!sample) return GST_FLOW_EOS;
  // After an accurate seek the demuxer starts at the key frame before the
  // position; JPEG frames carry no duration, so the sink does not clip
  // them: the ones before the position are left out here, not sent at once.
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  const GstSegment* segment = gst_sample_get_segment(sample);
  // A frame damaged in the file is left out, as every reader of recordings
  // leaves it out (segment_reader.h).
  if ((segment && GST_BUFFER_PTS_IS_VALID(buffer) && GST_BUFFER_PTS(buffer) < segment->start) ||
      !isWholeJpeg(buffer)) {
    gst_sample_unref(sample);
    return GST_FLOW_OK;
  }
  struct Delivery {
    PlaybackStream* stream;
    std::weak_ptr<bool> alive;
    GstBuffer* jpeg;
  };
  auto* delivery = new Delivery{self, self->alive_, gst_buffer_ref(gst_sample_get_buffer(sample))};
  gst_sample_unref(sample);
  g_main_context_invoke_full(
      nullptr, G_PRIORITY_DEFAULT,
      [](gpointer d) -> gboolean {
        auto* frame = static_cast<Delivery*>(d);
        if (!frame->alive.expired()) {
          GstClockTime pts = GST_BUFFER_PTS(frame->jpeg);
          double position =
              GST_CLOCK_TIME_IS_VALID(pts) ? static_cast<double>(pts) / GST_SECOND : 0.0;
          frame->stream->callbacks_.frame(frame->jpeg, position);
        }
        return G_SOURCE_REMOVE;
      },
      delivery,
      [](gpointer d) {
        auto* frame = static_cast<Delivery*>(d);
        gst_buffer_unref(frame->jpeg);
        delete frame;
      });
  return GST_FLOW_OK;
}

gboolean PlaybackStream::onBusMessage(GstBus*, GstMessage* message, gpointer data) {
  auto* self = static_cast<PlaybackStream*>(data);
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_EOS) {
    self->busWatch_ = 0;
    self->callbacks_.ended("");
    return G_SOURCE_REMOVE;
  }
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    GError* error = nullptr;
    gst_message_parse_error(message, &error, nullptr);
    std::string text = error ? error->message : "replay failed";
    g_clear_error(&error);
    self->busWatch_ = 0;
    self->callbacks_.ended(text);
    return G_SOURCE_REMOVE;
  }
  return G_SOURCE_CONTINUE;
}

}  // namespace wircam::recorder
