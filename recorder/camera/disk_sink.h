// The end of a recorded file's pipeline when its bytes are written by the
// filesystem's DiskWriter: a sink that hands each of the muxer's buffers
// over at the offset the muxer is at (it seeks back at its end to finish
// the file's headers), answers that the file is seekable as filesink does,
// and at the end closes the file once its writes are done. A write's
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

// A sink for `file` (opened by DiskWriter::open); `closed` runs with it
// once the file is written and closed, after the muxer's end: on the
// writer's thread, or on the streaming thread after diskSinkWaitsAtEnd.
GstElement* makeDiskSink(std::shared_ptr<DiskWriter> writer, std::shared_ptr<DiskWriter::File> file,
                         std::shared_ptr<DiskBudget> budget,
                         std::function<void(GstElement* sink)> closed);

// At the muxer's end the sink waits for its file to be written (the run's
// end: the pipeline's EOS then means every file is on the disk). Without
// it the file is closed when written, and the muxer's thread goes on.
// Any other element: nothing.
void diskSinkWaitsAtEnd(GstElement* sink);

}  // namespace wircam::recorder
