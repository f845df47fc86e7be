// Holds a GstObject's lock for a scope (as libcamera's GLibLocker does).
#pragma once

#include <gst/gst.h>

namespace wircam::gst {

class GLibLocker {
 public:
  explicit GLibLocker(gpointer object) : object_(GST_OBJECT(object)) { GST_OBJECT_LOCK(object_); }
  ~GLibLocker() { GST_OBJECT_UNLOCK(object_); }
  GLibLocker(const GLibLocker&) = delete;
  GLibLocker& operator=(const GLibLocker&) = delete;

 private:
  GstObject* object_;
};

}  // namespace wircam::gst
