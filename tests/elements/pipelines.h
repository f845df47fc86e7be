// What the element tests do with whole pipelines: build one from a launch
// line, and read the first error or warning its bus carries.
#pragma once

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "shell_command.h"

namespace wircam::testing {

inline GstElement* launch(const std::string& description) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  EXPECT_EQ(error, nullptr) << (error ? error->message : "");
  return pipeline;
}

// The first error or warning (of the types asked for) on the bus within
// `timeout` as "message | debug", or "" when none came.
inline std::string busMessage(GstElement* pipeline, std::chrono::milliseconds timeout,
                              GstMessageType type = GST_MESSAGE_ERROR) {
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* message = gst_bus_timed_pop_filtered(bus, timeout.count() * GST_MSECOND, type);
  std::string text;
  if (message) {
    GError* error = nullptr;
    gchar* debug = nullptr;
    if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_WARNING)
      gst_message_parse_warning(message, &error, &debug);
    else
      gst_message_parse_error(message, &error, &debug);
    text = std::string(error->message) + " | " + (debug ? debug : "");
    g_error_free(error);
    g_free(debug);
    gst_message_unref(message);
  }
  gst_object_unref(bus);
  return text;
}

// Plays `description` until its first error (as busMessage gives it, "" if
// none within `timeout`), then stops it.
inline std::string firstErrorOf(const std::string& description, std::chrono::milliseconds timeout) {
  GstElement* pipeline = launch(description);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::string error = busMessage(pipeline, timeout);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  return error;
}

}  // namespace wircam::testing
