#include "camera/gst_json.h"

namespace wircam::recorder {

namespace {

nlohmann::json toJson(const GValue* value);

nlohmann::json fieldsOf(const GstStructure* structure) {
  nlohmann::json object = nlohmann::json::object();
  gst_structure_foreach(
      structure,
      [](GQuark field, const GValue* v, gpointer data) -> gboolean {
        (*static_cast<nlohmann::json*>(data))[g_quark_to_string(field)] = toJson(v);
        return TRUE;
      },
      &object);
  return object;
}

nlohmann::json toJson(const GValue* value) {
  GType type = G_VALUE_TYPE(value);
  if (type == G_TYPE_UINT64) return g_value_get_uint64(value);
  if (type == G_TYPE_INT64) return g_value_get_int64(value);
  if (type == G_TYPE_UINT) return g_value_get_uint(value);
  if (type == G_TYPE_INT) return g_value_get_int(value);
  if (type == G_TYPE_DOUBLE) return g_value_get_double(value);
  if (type == G_TYPE_BOOLEAN) return static_cast<bool>(g_value_get_boolean(value));
  if (type == G_TYPE_STRING) return g_value_get_string(value) ? g_value_get_string(value) : "";
  if (type == GST_TYPE_LIST || type == GST_TYPE_ARRAY) {
    bool list = type == GST_TYPE_LIST;
    nlohmann::json array = nlohmann::json::array();
    guint size = list ? gst_value_list_get_size(value) : gst_value_array_get_size(value);
    for (guint i = 0; i < size; ++i)
      array.push_back(
          toJson(list ? gst_value_list_get_value(value, i) : gst_value_array_get_value(value, i)));
    return array;
  }
  if (type == GST_TYPE_STRUCTURE) return fieldsOf(gst_value_get_structure(value));
  gchar* text = gst_value_serialize(value);
  std::string serialized = text ? text : "";
  g_free(text);
  return serialized;
}

}  // namespace

nlohmann::json toJson(const GstStructure* structure) { return fieldsOf(structure); }

}  // namespace wircam::recorder
