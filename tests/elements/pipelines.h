// What the element tests do with whole pipelines: build one from a launch
// line (and read what its bus carries: bus_messages.h).
#pragma once

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "bus_messages.h"
#include "shell_command.h"

namespace wircam::testing {

inline GstElement* launch(const std::string& description) {
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  EXPECT_EQ(error, nullptr) << (error ? error->message : "");
  return pipeline;
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
