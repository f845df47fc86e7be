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

WircTagMeta* wirc_buffer_get_tag_meta(GstBuffer* buffer) {
  return buffer ? gst_buffer_get_wirc_tag_meta(buffer) : nullptr;
}

guint wirc_tag_meta_get_n_tags(const WircTagMeta* meta) { return meta ? meta->tags->len : 0; }

WircTag* wirc_tag_meta_get_tag(const WircTagMeta* meta, guint index) {
  if (!meta || index >= meta->tags->len) return nullptr;
  return &g_array_index(meta->tags, WircTag, index);
}

const gchar* wirc_tag_get_family(const WircTag* tag) { return tag ? tag->family : ""; }

gboolean wirc_tag_get_corner(const WircTag* tag, guint index, gdouble* x, gdouble* y) {
  if (!tag || index > 3) return FALSE;
  if (x) *x = tag->corners[2 * index];
  if (y) *y = tag->corners[2 * index + 1];
  return TRUE;
}
