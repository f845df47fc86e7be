#include "http/rtsp_token_auth.h"

#include "http/http_routes.h"

namespace wircam::recorder {

namespace {

struct TokenAuth {
  GstRTSPAuth parent;
  std::string* token;
  // The context borrows it (gst-rtsp-server does not ref a context's
  // token): it lives as long as the authentication object.
  GstRTSPToken* viewer;
};

struct TokenAuthClass {
  GstRTSPAuthClass parent;
};

G_DEFINE_TYPE(TokenAuth, token_auth, GST_TYPE_RTSP_AUTH)

gboolean authenticate(GstRTSPAuth* auth, GstRTSPContext* context) {
  auto* self = reinterpret_cast<TokenAuth*>(auth);
  context->token = nullptr;  // no token, no access: a 401
  gchar* authorization = nullptr;
  if (gst_rtsp_message_get_header(context->request, GST_RTSP_HDR_AUTHORIZATION, &authorization,
                                  0) == GST_RTSP_OK &&
      carriesToken(authorization, nullptr, *self->token))
    context->token = self->viewer;
  return TRUE;
}

void finalize(GObject* object) {
  auto* self = reinterpret_cast<TokenAuth*>(object);
  delete self->token;
  gst_rtsp_token_unref(self->viewer);
  G_OBJECT_CLASS(token_auth_parent_class)->finalize(object);
}

void token_auth_class_init(TokenAuthClass* klass) {
  G_OBJECT_CLASS(klass)->finalize = finalize;
  GST_RTSP_AUTH_CLASS(klass)->authenticate = authenticate;
}

void token_auth_init(TokenAuth* self) {
  self->token = new std::string;
  self->viewer = gst_rtsp_token_new(GST_RTSP_TOKEN_MEDIA_FACTORY_ROLE, G_TYPE_STRING,
                                    kRtspViewerRole, nullptr);
}

}  // namespace

GstRTSPAuth* rtspTokenAuth(const std::string& token) {
  auto* auth = static_cast<TokenAuth*>(g_object_new(token_auth_get_type(), nullptr));
  *auth->token = token;
  gst_rtsp_auth_set_supported_methods(GST_RTSP_AUTH(auth), GST_RTSP_AUTH_BASIC);
  gst_rtsp_auth_set_realm(GST_RTSP_AUTH(auth), "wirc-recorder");
  return GST_RTSP_AUTH(auth);
}

}  // namespace wircam::recorder
