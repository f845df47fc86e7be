// libmosquitto, opened when the first MQTT client starts instead of linked:
// with it come libssl and libcrypto, whose loading alone (relocations) keeps
// about 1.8 MB resident in every recorder, though most recorders never
// speak MQTT.
#pragma once

#include <mosquitto.h>

#include <string>

#include "common/expected.h"

namespace wircam::recorder {

// The functions the MQTT client calls, each once: (member, libmosquitto's name).
#define WIRCAM_MOSQUITTO_FUNCTIONS(X)                   \
  X(libInit, mosquitto_lib_init)                        \
  X(create, mosquitto_new)                              \
  X(destroy, mosquitto_destroy)                         \
  X(userDataSet, mosquitto_user_data_set)               \
  X(threadedSet, mosquitto_threaded_set)                \
  X(usernamePwSet, mosquitto_username_pw_set)           \
  X(tlsSet, mosquitto_tls_set)                          \
  X(willSet, mosquitto_will_set)                        \
  X(connectCallbackSet, mosquitto_connect_callback_set) \
  X(messageCallbackSet, mosquitto_message_callback_set) \
  X(publishCallbackSet, mosquitto_publish_callback_set) \
  X(connect, mosquitto_connect)                         \
  X(socket, mosquitto_socket)                           \
  X(loopRead, mosquitto_loop_read)                      \
  X(loopWrite, mosquitto_loop_write)                    \
  X(loopMisc, mosquitto_loop_misc)                      \
  X(wantWrite, mosquitto_want_write)                    \
  X(publish, mosquitto_publish)                         \
  X(subscribe, mosquitto_subscribe)                     \
  X(disconnect, mosquitto_disconnect)                   \
  X(strerror, mosquitto_strerror)                       \
  X(connackString, mosquitto_connack_string)

struct MosquittoLibrary {
#define WIRCAM_MOSQUITTO_MEMBER(member, symbol) decltype(&symbol) member = nullptr;
  WIRCAM_MOSQUITTO_FUNCTIONS(WIRCAM_MOSQUITTO_MEMBER)
#undef WIRCAM_MOSQUITTO_MEMBER
};

// The library, opened and initialised on the first call; or why it could
// not be (libmosquitto1 is not installed).
Expected<const MosquittoLibrary*, std::string> mosquittoLibrary();

}  // namespace wircam::recorder
