#include "camera/disk_sink.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

GST_DEBUG_CATEGORY_STATIC(wircam_disk_sink_debug);
#define GST_CAT_DEFAULT wircam_disk_sink_debug

namespace {

struct DiskSinkState {
  std::shared_ptr<wircam::recorder::DiskWriter> writer;
  std::shared_ptr<wircam::recorder::DiskWriter::File> file;
  std::shared_ptr<wircam::recorder::DiskBudget> budget;
  std::function<void(GstElement* sink)> closed;
  uint64_t offset = 0;  // where the muxer writes next, on the streaming thread
  // The muxer has ended and the file is closed. (A sink stopped before
  // that lets its writes go on: the file is closed after the last, when
  // the writer lets go of it.)
  bool finished = false;
  std::atomic<bool> waitAtEnd{false};  // diskSinkWaitsAtEnd()
};

}  // namespace

struct _WircamDiskSink {
  GstBaseSink parent;
  DiskSinkState* state;
};

G_DEFINE_TYPE(WircamDiskSink, wircam_disk_sink, GST_TYPE_BASE_SINK)

namespace {

// filesink's errors for the same faults: the camera tells a full disk by
// GST_RESOURCE_ERROR_NO_SPACE_LEFT.
void postWriteError(WircamDiskSink* self, int error) {
  if (error == ENOSPC || error == EDQUOT) {
    GST_ELEMENT_ERROR(self, RESOURCE, NO_SPACE_LEFT, ("No space left on the recording's disk."),
                      ("%s", std::strerror(error)));
  } else {
    GST_ELEMENT_ERROR(self, RESOURCE, WRITE, ("Cannot write the recording."),
                      ("%s", std::strerror(error)));
  }
}

GstFlowReturn render(GstBaseSink* sink, GstBuffer* buffer) {
  auto* self = WIRCAM_DISK_SINK(sink);
  DiskSinkState& state = *self->state;
  if (int error = wircam::recorder::DiskWriter::errorOf(*state.file)) {
    postWriteError(self, error);
    return GST_FLOW_ERROR;
  }
  state.writer->write(state.file, state.offset, buffer, state.budget);
  state.offset += gst_buffer_get_size(buffer);
  return GST_FLOW_OK;
}

// Waits for the file's writes, closes it, says so; once.
bool finish(WircamDiskSink* self) {
  DiskSinkState& state = *self->state;
  if (state.finished) return true;
  state.finished = true;
  int error = state.writer->close(state.file);
  if (error) {
    postWriteError(self, error);
    return false;
  }
  if (state.closed) state.closed(GST_ELEMENT(self));
  return true;
}

// The same, without waiting: on the writer's thread once the file is
// written (the sink kept until then).
void finishLater(WircamDiskSink* self) {
  DiskSinkState& state = *self->state;
  if (state.finished) return;
  state.finished = true;
  auto* sink = static_cast<WircamDiskSink*>(gst_object_ref(self));
  state.writer->closeWhenWritten(state.file, [sink, closed = state.closed](int error) {
    if (error)
      postWriteError(sink, error);
    else if (closed)
      closed(GST_ELEMENT(sink));
    gst_object_unref(sink);
  });
}

gboolean event(GstBaseSink* sink, GstEvent* event) {
  auto* self = WIRCAM_DISK_SINK(sink);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_SEGMENT: {
      // A muxer seeks by a new byte segment (matroskamux and mp4mux at
      // their end, to write the file's size and index).
      const GstSegment* segment = nullptr;
      gst_event_parse_segment(event, &segment);
      if (segment->format == GST_FORMAT_BYTES) self->state->offset = segment->start;
      break;
    }
    case GST_EVENT_EOS:
      // A file cut off mid-run must not hold the muxer's thread (the
      // camera's source) for a slow disk; at the run's end the pipeline's
      // EOS must mean every file is written.
      if (!self->state->waitAtEnd) {
        finishLater(self);
      } else if (!finish(self)) {
        gst_event_unref(event);
        return FALSE;
      }
      break;
    default:
      break;
  }
  return GST_BASE_SINK_CLASS(wircam_disk_sink_parent_class)->event(sink, event);
}

// The muxers write a file's size and index at its start once it ends, if
// the sink says it can seek (as filesink does).
gboolean query(GstBaseSink* sink, GstQuery* query) {
  if (GST_QUERY_TYPE(query) != GST_QUERY_SEEKING)
    return GST_BASE_SINK_CLASS(wircam_disk_sink_parent_class)->query(sink, query);
  GstFormat format;
  gst_query_parse_seeking(query, &format, nullptr, nullptr, nullptr);
  gst_query_set_seeking(query, format, format == GST_FORMAT_BYTES, 0, -1);
  return TRUE;
}

void finalize(GObject* object) {
  delete WIRCAM_DISK_SINK(object)->state;
  G_OBJECT_CLASS(wircam_disk_sink_parent_class)->finalize(object);
}

}  // namespace

static void wircam_disk_sink_class_init(WircamDiskSinkClass* klass) {
  GST_DEBUG_CATEGORY_INIT(wircam_disk_sink_debug, "wircamdisksink", 0,
                          "the recorder's files, written by their filesystem's thread");
  G_OBJECT_CLASS(klass)->finalize = finalize;
  auto* element = GST_ELEMENT_CLASS(klass);
  gst_element_class_set_static_metadata(
      element, "wircam disk sink", "Sink/File",
      "Hands a recorded file's bytes to the thread writing its filesystem", "wircam");
  static GstStaticPadTemplate sinkTemplate =
      GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS_ANY);
  gst_element_class_add_static_pad_template(element, &sinkTemplate);
  auto* base = GST_BASE_SINK_CLASS(klass);
  base->render = render;
  base->event = event;
  base->query = query;
}

static void wircam_disk_sink_init(WircamDiskSink* self) {
  self->state = new DiskSinkState;
  gst_base_sink_set_sync(GST_BASE_SINK(self), FALSE);
  // Not async: a sink added to a playing pipeline must not take it back to
  // PAUSED until its first buffer.
  gst_base_sink_set_async_enabled(GST_BASE_SINK(self), FALSE);
}

namespace wircam::recorder {

GstElement* makeDiskSink(std::shared_ptr<DiskWriter> writer, std::shared_ptr<DiskWriter::File> file,
                         std::shared_ptr<DiskBudget> budget,
                         std::function<void(GstElement* sink)> closed) {
  auto* sink = WIRCAM_DISK_SINK(g_object_new(wircam_disk_sink_get_type(), nullptr));
  DiskSinkState& state = *sink->state;
  state.writer = std::move(writer);
  state.file = std::move(file);
  state.budget = std::move(budget);
  state.closed = std::move(closed);
  return GST_ELEMENT(sink);
}

void diskSinkWaitsAtEnd(GstElement* sink) {
  if (WIRCAM_IS_DISK_SINK(sink)) WIRCAM_DISK_SINK(sink)->state->waitAtEnd = true;
}

}  // namespace wircam::recorder
