#include "wirc_uri.h"

#include <gst/gst.h>

#include <cstdlib>
#include <memory>

namespace wircam::gst {

std::string WircUri::toString() const {
  std::string text = "wirc://" + host;
  if (port != 1984) text += ":" + std::to_string(port);
  text += "/" + std::to_string(camera);
  if (!device.empty()) {
    gchar* escaped = g_uri_escape_string(device.c_str(), nullptr, FALSE);
    text += "?device=" + std::string(escaped);
    g_free(escaped);
  }
  return text;
}

Expected<WircUri, std::string> parseWircUri(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return unexpected("'" + text + "': " + why + " (wirc://HOST[:PORT]/CAMERA?device=NAME)");
  };
  std::unique_ptr<GstUri, decltype(&gst_uri_unref)> uri(gst_uri_from_string(text.c_str()),
                                                        gst_uri_unref);
  if (!uri || g_strcmp0(gst_uri_get_scheme(uri.get()), "wirc") != 0)
    return bad("not a wirc:// URI");
  WircUri parsed;
  if (const gchar* host = gst_uri_get_host(uri.get())) parsed.host = host;
  guint port = gst_uri_get_port(uri.get());
  if (port != GST_URI_NO_PORT) {
    if (port < 1 || port > 65535) return bad("a port is 1..65535");
    parsed.port = static_cast<uint16_t>(port);
  }
  gchar* path = gst_uri_get_path(uri.get());
  std::string camera = path ? path : "";
  g_free(path);
  if (!camera.empty() && camera.front() == '/') camera.erase(0, 1);
  if (!camera.empty()) {
    char* end = nullptr;
    long number = std::strtol(camera.c_str(), &end, 10);
    if (*end != '\0' || number < 0 || number > 255) return bad("the camera is 0..255");
    parsed.camera = static_cast<unsigned>(number);
  }
  if (GHashTable* query = gst_uri_get_query_table(uri.get())) {
    GHashTableIter it;
    gpointer key, value;
    g_hash_table_iter_init(&it, query);
    std::string unknown;
    while (g_hash_table_iter_next(&it, &key, &value)) {
      if (g_strcmp0(static_cast<const char*>(key), "device") == 0 && value)
        parsed.device = static_cast<const char*>(value);
      else
        unknown = static_cast<const char*>(key);
    }
    g_hash_table_unref(query);
    if (!unknown.empty()) return bad("unknown query '" + unknown + "'");
  }
  if (parsed.host.empty() && parsed.device.empty() && text.rfind("wirc:///", 0) != 0)
    return bad("no host");
  return parsed;
}

namespace {

GstURIType uriType(GType) { return GST_URI_SRC; }

const gchar* const* uriProtocols(GType) {
  static const gchar* const protocols[] = {"wirc", nullptr};
  return protocols;
}

gchar* getUri(GstURIHandler* handler) {
  gchar* host = nullptr;
  gchar* device = nullptr;
  guint port = 0, camera = 0;
  g_object_get(handler, "host", &host, "port", &port, "camera", &camera, "device", &device,
               nullptr);
  WircUri uri{.host = host ? host : "",
              .port = static_cast<uint16_t>(port),
              .camera = camera,
              .device = device ? device : ""};
  g_free(host);
  g_free(device);
  return g_strdup(uri.toString().c_str());
}

gboolean setUri(GstURIHandler* handler, const gchar* text, GError** error) {
  auto uri = parseWircUri(text ? text : "");
  if (!uri) {
    g_set_error(error, GST_URI_ERROR, GST_URI_ERROR_BAD_URI, "%s", uri.error().c_str());
    return FALSE;
  }
  GstState state, pending;
  {
    GstObject* element = GST_OBJECT(handler);
    GST_OBJECT_LOCK(element);
    state = GST_STATE(element);
    pending = GST_STATE_PENDING(element);
    GST_OBJECT_UNLOCK(element);
  }
  if (state > GST_STATE_READY || pending > GST_STATE_READY) {
    g_set_error(error, GST_URI_ERROR, GST_URI_ERROR_BAD_STATE,
                "the URI cannot change while wircsrc is PAUSED or PLAYING");
    return FALSE;
  }
  g_object_set(handler, "host", uri->host.c_str(), "port", guint{uri->port}, "camera", uri->camera,
               "device", uri->device.c_str(), nullptr);
  return TRUE;
}

}  // namespace

void initWircUriHandler(gpointer iface, gpointer) {
  auto* handler = static_cast<GstURIHandlerInterface*>(iface);
  handler->get_type = uriType;
  handler->get_protocols = uriProtocols;
  handler->get_uri = getUri;
  handler->set_uri = setUri;
}

}  // namespace wircam::gst
