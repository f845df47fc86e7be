#include "wirc_position_meta.h"

// Like WircTagMeta, carried by both plugins: looked up by name before it is
// registered.

GType wirc_position_meta_api_get_type(void) {
  static GType type = 0;
  if (g_once_init_enter(&type)) {
    GType found = g_type_from_name("WircPositionMetaAPI");
    if (!found) {
      static const gchar* tags[] = {nullptr};  // no tags: nothing a transform does voids it
      found = gst_meta_api_type_register("WircPositionMetaAPI", tags);
    }
    g_once_init_leave(&type, found);
  }
  return type;
}

static gboolean wirc_position_meta_init(GstMeta* meta, gpointer, GstBuffer*) {
  auto* position = reinterpret_cast<WircPositionMeta*>(meta);
  position->beacon = 0;
  position->x = position->y = position->z = position->dashboard_time = 0;
  position->running_time = GST_CLOCK_TIME_NONE;
  position->offset = 0;
  return TRUE;
}

static gboolean wirc_position_meta_transform(GstBuffer* destination, GstMeta* meta, GstBuffer*,
                                             GQuark, gpointer) {
  // Whatever happens to the pixels, the vehicle was where it was.
  auto* from = reinterpret_cast<WircPositionMeta*>(meta);
  WircPositionMeta* to = gst_buffer_add_wirc_position_meta(destination);
  GstMeta header = to->meta;
  *to = *from;
  to->meta = header;
  return TRUE;
}

const GstMetaInfo* wirc_position_meta_get_info(void) {
  static const GstMetaInfo* info = nullptr;
  if (g_once_init_enter(&info)) {
    const GstMetaInfo* found = gst_meta_get_info("WircPositionMeta");
    if (!found)
      found = gst_meta_register(WIRC_POSITION_META_API_TYPE, "WircPositionMeta",
                                sizeof(WircPositionMeta), wirc_position_meta_init, nullptr,
                                wirc_position_meta_transform);
    g_once_init_leave(&info, found);
  }
  return info;
}

WircPositionMeta* gst_buffer_add_wirc_position_meta(GstBuffer* buffer) {
  return reinterpret_cast<WircPositionMeta*>(
      gst_buffer_add_meta(buffer, wirc_position_meta_get_info(), nullptr));
}

guint wirc_buffer_get_n_position_metas(GstBuffer* buffer) {
  if (!buffer) return 0;
  return gst_buffer_get_n_meta(buffer, WIRC_POSITION_META_API_TYPE);
}

WircPositionMeta* wirc_buffer_get_position_meta(GstBuffer* buffer, guint index) {
  gpointer state = nullptr;
  guint seen = 0;
  while (GstMeta* meta =
             buffer ? gst_buffer_iterate_meta_filtered(buffer, &state, WIRC_POSITION_META_API_TYPE)
                    : nullptr)
    if (seen++ == index) return reinterpret_cast<WircPositionMeta*>(meta);
  return nullptr;
}
