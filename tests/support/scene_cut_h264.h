// An H.264 encoder that makes non-IDR I-frames (x264 at scene cuts: here
// every frame of noise is one) between IDRs a second apart, its frames as
// the recorder keeps them ("avc", whole access units): what a client that
// joins mid-stream must not start on. Its frames go to `tap` (the
// recorder's FrameTap); the pipeline is not started.
#pragma once

#include <gst/gst.h>

#include "camera/frame_tap.h"

namespace wircam::testing {

inline GstElement* sceneCutH264Into(recorder::FrameTap& tap) {
  GstElement* pipeline = gst_parse_launch(
      "videotestsrc pattern=snow is-live=true ! video/x-raw,width=160,height=120,framerate=30/1 "
      "! x264enc tune=zerolatency speed-preset=veryfast key-int-max=30 "
      "option-string=keyint=30:min-keyint=30:scenecut=100 ! h264parse "
      "! video/x-h264,stream-format=avc,alignment=au,profile=main ! fakesink name=out",
      nullptr);
  if (!pipeline) return nullptr;
  GstElement* out = gst_bin_get_by_name(GST_BIN(pipeline), "out");
  GstPad* pad = gst_element_get_static_pad(out, "sink");
  tap.attachPad(pad);
  gst_object_unref(pad);
  gst_object_unref(out);
  return pipeline;
}

}  // namespace wircam::testing
