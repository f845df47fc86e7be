#include "wirc_tag_meta.h"

#include <cstring>

// Both plugins (wirc and wircvision) carry this code, so registration first
// looks the types up by name: GLib refuses to register a name twice.

GType wirc_tag_meta_api_get_type(void) {
  static GType type = 0;
  if (g_once_init_enter(&type)) {
    GType found = g_type_from_name("WircTagMetaAPI");
    if (!found) {
      static const gchar* tags[] = {nullptr};  // coordinates: not valid after scaling
      found = gst_meta_api_type_register("WircTagMetaAPI", tags);
    }
    g_once_init_leave(&type, found);
  }
  return type;
}

static gboolean wirc_tag_meta_init(GstMeta* meta, gpointer, GstBuffer*) {
  auto* tagMeta = reinterpret_cast<WircTagMeta*>(meta);
  tagMeta->width = tagMeta->height = 0;
  tagMeta->tags = g_array_new(FALSE, TRUE, sizeof(WircTag));
  return TRUE;
}

static void wirc_tag_meta_free(GstMeta* meta, GstBuffer*) {
  g_array_unref(reinterpret_cast<WircTagMeta*>(meta)->tags);
}

static gboolean wirc_tag_meta_transform(GstBuffer* destination, GstMeta* meta, GstBuffer*,
                                        GQuark type, gpointer data) {
  // Copies keep the tags; a scale or crop would move them, so it drops them.
  if (!GST_META_TRANSFORM_IS_COPY(type)) return FALSE;
  (void)data;
  auto* from = reinterpret_cast<WircTagMeta*>(meta);
  WircTagMeta* to = gst_buffer_add_wirc_tag_meta(destination, from->width, from->height);
  g_array_append_vals(to->tags, from->tags->data, from->tags->len);
  return TRUE;
}

const GstMetaInfo* wirc_tag_meta_get_info(void) {
  static const GstMetaInfo* info = nullptr;
  if (g_once_init_enter(&info)) {
    const GstMetaInfo* found = gst_meta_get_info("WircTagMeta");
    if (!found)
      found = gst_meta_register(WIRC_TAG_META_API_TYPE, "WircTagMeta", sizeof(WircTagMeta),
                                wirc_tag_meta_init, wirc_tag_meta_free, wirc_tag_meta_transform);
    g_once_init_leave(&info, found);
  }
  return info;
}

WircTagMeta* gst_buffer_add_wirc_tag_meta(GstBuffer* buffer, guint width, guint height) {
  auto* meta = reinterpret_cast<WircTagMeta*>(
      gst_buffer_add_meta(buffer, wirc_tag_meta_get_info(), nullptr));
  meta->width = width;
  meta->height = height;
  return meta;
}
