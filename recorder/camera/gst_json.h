// GstStructure fields (element messages) as JSON, for telemetry and the
// web server.
#pragma once

#include <gst/gst.h>

#include <nlohmann/json.hpp>

namespace wircam::recorder {

// Lists, arrays and nested structures become arrays and objects; types
// JSON has no word for are written as GStreamer serializes them.
nlohmann::json toJson(const GstStructure* structure);

}  // namespace wircam::recorder
