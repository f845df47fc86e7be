// The end of a recorded file's pipeline when its bytes are written by the
// filesystem's DiskWriter: a sink that hands each of the muxer's buffers
// over at the offset the muxer is at (it seeks back at its end to finish
// the file's headers), answers that the file is seekable as filesink does,
// and at the end waits for the file's writes and closes it. A write's
// error (a full disk) becomes the element's error, as filesink's would.
#pragma once

#include <gst/base/gstbasesink.h>

#include <functional>
#include <memory>

#include "camera/disk_writer.h"

G_BEGIN_DECLS
G_DECLARE_FINAL_TYPE(WircamDiskSink, wircam_disk_sink, WIRCAM, DISK_SINK, GstBaseSink)
G_END_DECLS

namespace wircam::recorder {

// A sink for `file` (opened by DiskWriter::open); `closed` runs on the
// streaming thread once the file is written and closed, after the muxer's
// end.
GstElement* makeDiskSink(std::shared_ptr<DiskWriter> writer, std::shared_ptr<DiskWriter::File> file,
                         std::shared_ptr<DiskBudget> budget, std::function<void()> closed);

}  // namespace wircam::recorder
