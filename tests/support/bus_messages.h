// What a pipeline's bus says went wrong, for tests' failure messages: its
// errors and warnings as text.
#pragma once

#include <gst/gst.h>

#include <chrono>
#include <string>

namespace wircam::testing {

// `message` (an error or a warning) as "message | debug".
inline std::string problemText(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_WARNING)
    gst_message_parse_warning(message, &error, &debug);
  else
    gst_message_parse_error(message, &error, &debug);
  std::string text = std::string(error->message) + " | " + (debug ? debug : "");
  g_error_free(error);
  g_free(debug);
  return text;
}

// The first error or warning (of the types asked for) on the bus within
// `timeout`, or "" when none came.
inline std::string busMessage(GstElement* pipeline, std::chrono::milliseconds timeout,
                              GstMessageType type = GST_MESSAGE_ERROR) {
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* message = gst_bus_timed_pop_filtered(bus, timeout.count() * GST_MSECOND, type);
  std::string text;
  if (message) {
    text = problemText(message);
    gst_message_unref(message);
  }
  gst_object_unref(bus);
  return text;
}

// Every error and warning waiting on the bus, a line each, named by the
// element that posted it.
inline std::string busProblems(GstElement* pipeline) {
  std::string said;
  GstBus* bus = gst_element_get_bus(pipeline);
  while (GstMessage* message = gst_bus_pop_filtered(
             bus, static_cast<GstMessageType>(GST_MESSAGE_ERROR | GST_MESSAGE_WARNING))) {
    said +=
        std::string(GST_OBJECT_NAME(GST_MESSAGE_SRC(message))) + ": " + problemText(message) + "\n";
    gst_message_unref(message);
  }
  gst_object_unref(bus);
  return said;
}

}  // namespace wircam::testing
