// wirc://HOST[:PORT]/CAMERA?device=NAME — a WiRC camera as a URI, for
// playbin and gst-play-1.0 (wircsrc's GstURIHandler). An empty HOST
// (wirc:///0?device=rover) finds the device by discovery.
#pragma once

#include <glib.h>

#include <cstdint>
#include <string>

#include "common/expected.h"

namespace wircam::gst {

struct WircUri {
  std::string host;  // empty: discover
  uint16_t port = 1984;
  unsigned camera = 0;
  std::string device;  // the name or serial to pick when discovering

  std::string toString() const;
};

Expected<WircUri, std::string> parseWircUri(const std::string& uri);

// GstURIHandler's interface for an element with the host, port, camera and
// device properties (wircsrc); the URI cannot change past READY.
void initWircUriHandler(gpointer iface, gpointer);

}  // namespace wircam::gst
