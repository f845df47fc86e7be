/**
 * SECTION:element-tjpegdec
 *
 * Decodes JPEG frames with libjpeg-turbo's TurboJPEG API into GRAY8 (luma
 * only: the chroma is never transformed, the fastest input for
 * apriltagdetect), I420 (from 4:2:0 or grayscale JPEGs), RGB or BGRx, in the
 * format downstream prefers, optionally scaled by 1/2, 1/4 or 1/8 during
 * decoding. Output buffers come from a pool. A corrupt frame is dropped with a
 * warning; the stream goes on.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 wircsrc host=127.0.0.1 ! tjpegdec ! video/x-raw,format=GRAY8 ! apriltagdetect ! fakesink
 * ]|
 * |[
 * gst-launch-1.0 wircsrc host=127.0.0.1 ! tjpegdec scale=1/2 ! videoconvert ! autovideosink
 * ]|
 */
#include "gsttjpegdec.h"

#include <turbojpeg.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "gst_scoped.h"

GST_DEBUG_CATEGORY_STATIC(tjpeg_dec_debug);
#define GST_CAT_DEFAULT tjpeg_dec_debug

namespace {

enum Scale { kScale1 = 1, kScale2 = 2, kScale4 = 4, kScale8 = 8 };
#define DEFAULT_SCALE kScale1

enum { PROP_0, PROP_SCALE };

GType scale_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {{kScale1, "Full size", "1"},
                                      {kScale2, "Half size", "1/2"},
                                      {kScale4, "Quarter size", "1/4"},
                                      {kScale8, "One eighth", "1/8"},
                                      {0, nullptr, nullptr}};
  if (g_once_init_enter(&type))
    g_once_init_leave(&type, g_enum_register_static("GstTjpegDecScale", values));
  return type;
}

struct TjpegDecState {
  int scale = DEFAULT_SCALE;  // guarded by the object lock
  // Streaming thread only.
  std::unique_ptr<void, decltype(&tjDestroy)> decoder{nullptr, tjDestroy};
  GstVideoCodecState* input = nullptr;
  int width = 0;  // of the output caps
  int height = 0;
  GstVideoFormat format = GST_VIDEO_FORMAT_UNKNOWN;
};

}  // namespace

struct _GstTjpegDec {
  GstVideoDecoder parent;
  TjpegDecState* state;
};

G_DEFINE_TYPE(GstTjpegDec, gst_tjpeg_dec, GST_TYPE_VIDEO_DECODER)

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS("image/jpeg"));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS,
                            GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("{ I420, GRAY8, RGB, BGRx }")));

static gboolean gst_tjpeg_dec_start(GstVideoDecoder* decoder) {
  auto* state = GST_TJPEG_DEC(decoder)->state;
  state->decoder.reset(tjInitDecompress());
  state->width = state->height = 0;
  return state->decoder != nullptr;
}

static gboolean gst_tjpeg_dec_stop(GstVideoDecoder* decoder) {
  auto* state = GST_TJPEG_DEC(decoder)->state;
  state->decoder.reset();
  g_clear_pointer(&state->input, gst_video_codec_state_unref);
  return TRUE;
}

static gboolean gst_tjpeg_dec_set_format(GstVideoDecoder* decoder, GstVideoCodecState* input) {
  auto* state = GST_TJPEG_DEC(decoder)->state;
  g_clear_pointer(&state->input, gst_video_codec_state_unref);
  state->input = gst_video_codec_state_ref(input);
  state->width = state->height = 0;  // renegotiate with the next frame
  return TRUE;
}

// The first of our formats in downstream's order of preference.
static GstVideoFormat preferred_format(GstVideoDecoder* decoder) {
  GstCaps* ours = gst_pad_get_pad_template_caps(GST_VIDEO_DECODER_SRC_PAD(decoder));
  GstCaps* peer = gst_pad_peer_query_caps(GST_VIDEO_DECODER_SRC_PAD(decoder), nullptr);
  GstCaps* both = gst_caps_intersect_full(peer, ours, GST_CAPS_INTERSECT_FIRST);
  GstVideoFormat format = GST_VIDEO_FORMAT_I420;
  if (!gst_caps_is_empty(both)) {
    both = gst_caps_fixate(both);
    if (const gchar* name = gst_structure_get_string(gst_caps_get_structure(both, 0), "format"))
      format = gst_video_format_from_string(name);
  }
  gst_caps_unref(both);
  gst_caps_unref(peer);
  gst_caps_unref(ours);
  return format;
}

static GstFlowReturn drop_with_warning(GstVideoDecoder* decoder, GstVideoCodecFrame* frame,
                                       const char* why) {
  GST_ELEMENT_WARNING(decoder, STREAM, DECODE, ("Dropped a corrupt JPEG frame"), ("%s", why));
  // Before the first good frame there are no caps yet: dropping would push
  // the pending segment without them, so the frame is only released.
  if (!gst_pad_has_current_caps(GST_VIDEO_DECODER_SRC_PAD(decoder))) {
    gst_video_decoder_release_frame(decoder, frame);
    return GST_FLOW_OK;
  }
  return gst_video_decoder_drop_frame(decoder, frame);
}

namespace {

using wircam::gst::ScopedBufferMap;
using wircam::gst::ScopedVideoFrameMap;

struct JpegHeader {
  int width = 0, height = 0, subsampling = 0;
};

// A whole JPEG ends with its end-of-image marker (FF D9), padding after it
// aside. One cut short decodes with only a warning, its missing rows grey
// (a file's frame cut to a third came out so, a stranger's trial): a
// picture the detector must not read.
bool ends_whole(const ScopedBufferMap& in) {
  gsize end = in.size();
  while (end > 0 && in.data()[end - 1] == 0x00) --end;
  return end >= 2 && in.data()[end - 2] == 0xFF && in.data()[end - 1] == 0xD9;
}

// The JPEG's size and subsampling, or nothing (the handle is renewed: a
// failed call can leave it mid-frame).
std::optional<JpegHeader> read_header(TjpegDecState* state, const ScopedBufferMap& in,
                                      std::string* why) {
  JpegHeader header;
  int colorspace = 0;
  if (tjDecompressHeader3(state->decoder.get(), in.data(), in.size(), &header.width, &header.height,
                          &header.subsampling, &colorspace) == 0 &&
      header.width > 0 && header.height > 0)
    return header;
  *why = tjGetErrorStr2(state->decoder.get());
  state->decoder.reset(tjInitDecompress());
  return std::nullopt;
}

// Sets (again) the output caps when the decoded size changes or none are set.
bool ensure_output_state(GstVideoDecoder* decoder, TjpegDecState* state, int width, int height) {
  if (width == state->width && height == state->height &&
      gst_pad_has_current_caps(GST_VIDEO_DECODER_SRC_PAD(decoder)))
    return true;
  state->format = preferred_format(decoder);
  GstVideoCodecState* output =
      gst_video_decoder_set_output_state(decoder, state->format, width, height, state->input);
  gst_video_codec_state_unref(output);
  if (!gst_video_decoder_negotiate(decoder)) return false;
  state->width = width;
  state->height = height;
  return true;
}

// Decodes into the mapped output frame; TurboJPEG's return code.
int decode_into(TjpegDecState* state, const ScopedBufferMap& in, const JpegHeader& header,
                GstVideoFrame* video) {
  tjhandle tj = state->decoder.get();
  if (state->format != GST_VIDEO_FORMAT_I420) {
    int pixelFormat = state->format == GST_VIDEO_FORMAT_GRAY8 ? TJPF_GRAY
                      : state->format == GST_VIDEO_FORMAT_RGB ? TJPF_RGB
                                                              : TJPF_BGRX;
    return tjDecompress2(tj, in.data(), in.size(),
                         static_cast<unsigned char*>(GST_VIDEO_FRAME_PLANE_DATA(video, 0)),
                         state->width, GST_VIDEO_FRAME_PLANE_STRIDE(video, 0), state->height,
                         pixelFormat, TJFLAG_FASTDCT);
  }
  unsigned char* planes[3];
  int strides[3];
  for (int p = 0; p < 3; ++p) {
    planes[p] = static_cast<unsigned char*>(GST_VIDEO_FRAME_PLANE_DATA(video, p));
    strides[p] = GST_VIDEO_FRAME_PLANE_STRIDE(video, p);
  }
  int rc = tjDecompressToYUVPlanes(tj, in.data(), in.size(), planes, state->width, strides,
                                   state->height, TJFLAG_FASTDCT);
  if (header.subsampling == TJSAMP_GRAY) {  // a grayscale JPEG has no chroma: make it neutral
    for (int p = 1; p < 3; ++p)
      for (int y = 0; y < GST_VIDEO_FRAME_COMP_HEIGHT(video, p); ++y)
        memset(planes[p] + y * strides[p], 128, GST_VIDEO_FRAME_COMP_WIDTH(video, p));
  }
  return rc;
}

}  // namespace

static GstFlowReturn gst_tjpeg_dec_handle_frame(GstVideoDecoder* decoder,
                                                GstVideoCodecFrame* frame) {
  auto* self = GST_TJPEG_DEC(decoder);
  auto* state = self->state;
  ScopedBufferMap in(frame->input_buffer, GST_MAP_READ);
  if (!in) return drop_with_warning(decoder, frame, "unreadable buffer");
  std::string why;
  auto header = read_header(state, in, &why);
  if (!header) return drop_with_warning(decoder, frame, why.c_str());
  if (!ends_whole(in))
    return drop_with_warning(decoder, frame, "cut short: no end-of-image marker");

  int scale;
  {
    GST_OBJECT_LOCK(self);
    scale = state->scale;
    GST_OBJECT_UNLOCK(self);
  }
  tjscalingfactor factor{1, scale};
  if (!ensure_output_state(decoder, state, TJSCALED(header->width, factor),
                           TJSCALED(header->height, factor))) {
    gst_video_decoder_drop_frame(decoder, frame);
    return GST_FLOW_NOT_NEGOTIATED;
  }
  if (state->format == GST_VIDEO_FORMAT_I420 && header->subsampling != TJSAMP_420 &&
      header->subsampling != TJSAMP_GRAY) {
    gst_video_decoder_drop_frame(decoder, frame);
    GST_ELEMENT_ERROR(
        decoder, STREAM, FORMAT, ("tjpegdec gives I420 only for 4:2:0 or grayscale JPEGs"),
        ("This stream has TurboJPEG subsampling %d: ask for GRAY8, RGB or BGRx instead "
         "(e.g. tjpegdec ! video/x-raw,format=RGB)",
         header->subsampling));
    return GST_FLOW_NOT_NEGOTIATED;
  }

  GstFlowReturn flow = gst_video_decoder_allocate_output_frame(decoder, frame);
  if (flow != GST_FLOW_OK) {
    gst_video_decoder_drop_frame(decoder, frame);
    return flow;
  }
  int rc;
  {
    GstVideoCodecState* output = gst_video_decoder_get_output_state(decoder);
    ScopedVideoFrameMap video(&output->info, frame->output_buffer, GST_MAP_WRITE);
    gst_video_codec_state_unref(output);
    if (!video) return drop_with_warning(decoder, frame, "unwritable output buffer");
    rc = decode_into(state, in, *header, video.get());
  }
  // TurboJPEG warnings (e.g. a few corrupt bytes) still give a full image.
  tjhandle tj = state->decoder.get();
  if (rc != 0 && tjGetErrorCode(tj) == TJERR_FATAL) {
    why = tjGetErrorStr2(tj);
    state->decoder.reset(tjInitDecompress());
    return drop_with_warning(decoder, frame, why.c_str());
  }
  if (rc != 0) GST_DEBUG_OBJECT(self, "decoded with a warning: %s", tjGetErrorStr2(tj));
  return gst_video_decoder_finish_frame(decoder, frame);
}

static void gst_tjpeg_dec_set_property(GObject* object, guint id, const GValue* value,
                                       GParamSpec* pspec) {
  auto* self = GST_TJPEG_DEC(object);
  if (id != PROP_SCALE) {
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
    return;
  }
  // A new scale gives the next frame a new size, which renegotiates: the
  // streaming thread's width and height are its own.
  GST_OBJECT_LOCK(self);
  self->state->scale = g_value_get_enum(value);
  GST_OBJECT_UNLOCK(self);
}

static void gst_tjpeg_dec_get_property(GObject* object, guint id, GValue* value,
                                       GParamSpec* pspec) {
  auto* self = GST_TJPEG_DEC(object);
  if (id != PROP_SCALE) {
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
    return;
  }
  GST_OBJECT_LOCK(self);
  g_value_set_enum(value, self->state->scale);
  GST_OBJECT_UNLOCK(self);
}

static void gst_tjpeg_dec_finalize(GObject* object) {
  delete GST_TJPEG_DEC(object)->state;
  G_OBJECT_CLASS(gst_tjpeg_dec_parent_class)->finalize(object);
}

static void gst_tjpeg_dec_init(GstTjpegDec* self) {
  self->state = new TjpegDecState();
  gst_video_decoder_set_packetized(GST_VIDEO_DECODER(self), TRUE);
  gst_video_decoder_set_use_default_pad_acceptcaps(GST_VIDEO_DECODER_CAST(self), TRUE);
  GST_PAD_SET_ACCEPT_TEMPLATE(GST_VIDEO_DECODER_SINK_PAD(self));
}

static void gst_tjpeg_dec_class_init(GstTjpegDecClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  auto* decoder = GST_VIDEO_DECODER_CLASS(klass);
  gobject->set_property = gst_tjpeg_dec_set_property;
  gobject->get_property = gst_tjpeg_dec_get_property;
  gobject->finalize = gst_tjpeg_dec_finalize;
  g_object_class_install_property(
      gobject, PROP_SCALE,
      g_param_spec_enum("scale", "Scale",
                        "Decode at this fraction of the JPEG's size (1, 1/2, 1/4, 1/8): "
                        "smaller is much faster",
                        scale_get_type(), DEFAULT_SCALE,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));
  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "TurboJPEG decoder", "Codec/Decoder/Image",
      "Decodes JPEG to GRAY8, I420, RGB or BGRx with libjpeg-turbo, optionally scaled",
      "wircam authors");
  decoder->start = gst_tjpeg_dec_start;
  decoder->stop = gst_tjpeg_dec_stop;
  decoder->set_format = gst_tjpeg_dec_set_format;
  decoder->handle_frame = gst_tjpeg_dec_handle_frame;
  GST_DEBUG_CATEGORY_INIT(tjpeg_dec_debug, "tjpegdec", 0, "TurboJPEG decoder");
}
