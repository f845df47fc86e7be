#include "http/head_watch_stream.h"

#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "http/request_head_framer.h"

namespace wircam::recorder {

namespace {

// The drain's bounds: what a client that is told no sends meanwhile.
constexpr size_t kDrainBytes = 1 << 20;
constexpr std::chrono::milliseconds kDrainTime{1000};
constexpr size_t kReadBlock = 16 * 1024;

struct Drain {
  GSocketConnection* connection;  // owned reference
  size_t drained = 0;
  GSource* readable = nullptr;
  guint timer = 0;
};

void endDrain(Drain* drain) {
  if (drain->timer) g_source_remove(drain->timer);
  g_source_destroy(drain->readable);
  g_source_unref(drain->readable);
  g_io_stream_close(G_IO_STREAM(drain->connection), nullptr, nullptr);
  g_object_unref(drain->connection);
  delete drain;
}

gboolean drainSome(GSocket* socket, GIOCondition, gpointer data) {
  auto* drain = static_cast<Drain*>(data);
  char sink[kReadBlock];
  ssize_t n;
  while ((n = recv(g_socket_get_fd(socket), sink, sizeof sink, MSG_DONTWAIT)) > 0)
    if ((drain->drained += static_cast<size_t>(n)) >= kDrainBytes) break;
  bool more = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
  if (more && drain->drained < kDrainBytes) return G_SOURCE_CONTINUE;
  endDrain(drain);
  return G_SOURCE_REMOVE;
}

// The answer has been written: the writing side is shut, the reading side
// read and dropped for at most kDrainTime or kDrainBytes, then closed.
void drainThenClose(GSocketConnection* connection) {
  GSocket* socket = g_socket_connection_get_socket(connection);
  g_socket_shutdown(socket, FALSE, TRUE, nullptr);
  auto* drain = new Drain{G_SOCKET_CONNECTION(g_object_ref(connection))};
  drain->readable = g_socket_create_source(socket, G_IO_IN, nullptr);
  g_source_set_callback(drain->readable, G_SOURCE_FUNC(+drainSome), drain, nullptr);
  g_source_attach(drain->readable, nullptr);
  drain->timer = g_timeout_add(
      static_cast<guint>(kDrainTime.count()),
      [](gpointer data) -> gboolean {
        auto* d = static_cast<Drain*>(data);
        d->timer = 0;
        endDrain(d);
        return G_SOURCE_REMOVE;
      },
      drain);
}

}  // namespace

}  // namespace wircam::recorder

// The input stream: a GFilterInputStream over the connection's (or TLS's)
// input, pollable as libsoup needs it, that hands on what the framer lets
// through.
struct WircamHeadWatchInput {
  GFilterInputStream parent;
  wircam::recorder::RequestHeadFramer* framer;
  std::string* ready;             // let through, not yet read by libsoup
  bool ended;                     // the client's end was read
  GIOStream* watched;             // owned: closed with this stream
  GSocketConnection* connection;  // owned: drained when due
};
struct WircamHeadWatchInputClass {
  GFilterInputStreamClass parent_class;
};

static void wircam_head_watch_input_pollable_init(GPollableInputStreamInterface* iface);
G_DEFINE_TYPE_WITH_CODE(WircamHeadWatchInput, wircam_head_watch_input, G_TYPE_FILTER_INPUT_STREAM,
                        G_IMPLEMENT_INTERFACE(G_TYPE_POLLABLE_INPUT_STREAM,
                                              wircam_head_watch_input_pollable_init))

namespace {

using wircam::recorder::kReadBlock;

WircamHeadWatchInput* watchOf(gpointer stream) {
  return reinterpret_cast<WircamHeadWatchInput*>(stream);
}

GInputStream* baseOf(WircamHeadWatchInput* self) {
  return G_FILTER_INPUT_STREAM(self)->base_stream;
}

gssize handOut(WircamHeadWatchInput* self, void* buffer, gsize count) {
  gsize n = std::min(count, self->ready->size());
  std::memcpy(buffer, self->ready->data(), n);
  self->ready->erase(0, n);
  return static_cast<gssize>(n);
}

// Reads from the client until something is let through, the client ends,
// or (without blocking) nothing more is there.
gssize readThrough(WircamHeadWatchInput* self, void* buffer, gsize count, bool blocking,
                   GCancellable* cancellable, GError** error) {
  char block[kReadBlock];
  while (self->ready->empty() && !self->ended) {
    gssize n = blocking ? g_input_stream_read(baseOf(self), block, sizeof block, cancellable, error)
                        : g_pollable_input_stream_read_nonblocking(
                              G_POLLABLE_INPUT_STREAM(baseOf(self)), block, sizeof block,
                              cancellable, error);
    if (n < 0) return -1;  // (WOULD_BLOCK among them)
    if (n == 0) {
      self->framer->end(*self->ready);
      self->ended = true;
    } else {
      self->framer->feed(std::string_view(block, static_cast<size_t>(n)), *self->ready);
    }
  }
  return handOut(self, buffer, count);
}

gssize readBlocking(GInputStream* stream, void* buffer, gsize count, GCancellable* cancellable,
                    GError** error) {
  return readThrough(watchOf(stream), buffer, count, true, cancellable, error);
}

gboolean closeWatched(GInputStream* stream, GCancellable*, GError**) {
  auto* self = watchOf(stream);
  if (self->framer->dropping()) {
    // An overlong head was answered: its rest may still be on its way.
    wircam::recorder::drainThenClose(self->connection);
  } else {
    g_io_stream_close(self->watched, nullptr, nullptr);
  }
  return TRUE;
}

void finalizeWatch(GObject* object) {
  auto* self = watchOf(object);
  delete self->framer;
  delete self->ready;
  g_clear_object(&self->watched);
  g_clear_object(&self->connection);
  G_OBJECT_CLASS(wircam_head_watch_input_parent_class)->finalize(object);
}

gboolean canPoll(GPollableInputStream* stream) {
  return g_pollable_input_stream_can_poll(G_POLLABLE_INPUT_STREAM(baseOf(watchOf(stream))));
}

gboolean isReadable(GPollableInputStream* stream) {
  auto* self = watchOf(stream);
  return !self->ready->empty() || self->ended ||
         g_pollable_input_stream_is_readable(G_POLLABLE_INPUT_STREAM(baseOf(self)));
}

GSource* createSource(GPollableInputStream* stream, GCancellable* cancellable) {
  auto* self = watchOf(stream);
  // Bytes let through and not read yet: readable now, whatever the client does.
  GSource* child = !self->ready->empty() || self->ended
                       ? g_timeout_source_new(0)
                       : g_pollable_input_stream_create_source(
                             G_POLLABLE_INPUT_STREAM(baseOf(self)), cancellable);
  GSource* source = g_pollable_source_new_full(stream, child, cancellable);
  g_source_unref(child);
  return source;
}

gssize readNonblocking(GPollableInputStream* stream, void* buffer, gsize count, GError** error) {
  return readThrough(watchOf(stream), buffer, count, false, nullptr, error);
}

}  // namespace

static void wircam_head_watch_input_class_init(WircamHeadWatchInputClass* klass) {
  G_OBJECT_CLASS(klass)->finalize = finalizeWatch;
  G_INPUT_STREAM_CLASS(klass)->read_fn = readBlocking;
  G_INPUT_STREAM_CLASS(klass)->close_fn = closeWatched;
}

static void wircam_head_watch_input_init(WircamHeadWatchInput* self) {
  self->framer = new wircam::recorder::RequestHeadFramer();
  self->ready = new std::string();
  self->ended = false;
  self->watched = nullptr;
  self->connection = nullptr;
}

static void wircam_head_watch_input_pollable_init(GPollableInputStreamInterface* iface) {
  iface->can_poll = canPoll;
  iface->is_readable = isReadable;
  iface->create_source = createSource;
  iface->read_nonblocking = readNonblocking;
}

// The stream libsoup is given: the watched input and the connection's
// output. Closed on the caller's thread, even when asked asynchronously
// (libsoup's WebSockets do): GIOStream's default would close it on a
// worker thread, one more thread for the server to keep.
struct WircamHeadWatchIOStream {
  GIOStream parent;
  GInputStream* input;    // owned
  GOutputStream* output;  // owned
};
struct WircamHeadWatchIOStreamClass {
  GIOStreamClass parent_class;
};
G_DEFINE_TYPE(WircamHeadWatchIOStream, wircam_head_watch_io_stream, G_TYPE_IO_STREAM)

namespace {

WircamHeadWatchIOStream* ioOf(gpointer stream) {
  return reinterpret_cast<WircamHeadWatchIOStream*>(stream);
}

GInputStream* inputOf(GIOStream* stream) { return ioOf(stream)->input; }
GOutputStream* outputOf(GIOStream* stream) { return ioOf(stream)->output; }

gboolean closeBoth(GIOStream* stream, GCancellable* cancellable, GError**) {
  // The output first (what libsoup wrote is flushed), then the input, whose
  // closing closes the connection (or drains it first).
  g_output_stream_close(outputOf(stream), cancellable, nullptr);
  g_input_stream_close(inputOf(stream), cancellable, nullptr);
  return TRUE;
}

void closeNow(GIOStream* stream, int, GCancellable* cancellable, GAsyncReadyCallback callback,
              gpointer data) {
  GTask* task = g_task_new(stream, cancellable, callback, data);
  g_task_return_boolean(task, closeBoth(stream, cancellable, nullptr));
  g_object_unref(task);
}

gboolean closedNow(GIOStream*, GAsyncResult* result, GError** error) {
  return g_task_propagate_boolean(G_TASK(result), error);
}

void finalizeIo(GObject* object) {
  g_clear_object(&ioOf(object)->input);
  g_clear_object(&ioOf(object)->output);
  G_OBJECT_CLASS(wircam_head_watch_io_stream_parent_class)->finalize(object);
}

}  // namespace

static void wircam_head_watch_io_stream_class_init(WircamHeadWatchIOStreamClass* klass) {
  G_OBJECT_CLASS(klass)->finalize = finalizeIo;
  G_IO_STREAM_CLASS(klass)->get_input_stream = inputOf;
  G_IO_STREAM_CLASS(klass)->get_output_stream = outputOf;
  G_IO_STREAM_CLASS(klass)->close_fn = closeBoth;
  G_IO_STREAM_CLASS(klass)->close_async = closeNow;
  G_IO_STREAM_CLASS(klass)->close_finish = closedNow;
}

static void wircam_head_watch_io_stream_init(WircamHeadWatchIOStream* self) {
  self->input = nullptr;
  self->output = nullptr;
}

namespace wircam::recorder {

GIOStream* watchRequestHeads(GIOStream* stream, GSocketConnection* connection) {
  auto* input = watchOf(g_object_new(wircam_head_watch_input_get_type(), "base-stream",
                                     g_io_stream_get_input_stream(stream), "close-base-stream",
                                     FALSE, nullptr));
  input->watched = G_IO_STREAM(g_object_ref(stream));
  input->connection = G_SOCKET_CONNECTION(g_object_ref(connection));
  auto* watched = ioOf(g_object_new(wircam_head_watch_io_stream_get_type(), nullptr));
  watched->input = G_INPUT_STREAM(input);
  watched->output = G_OUTPUT_STREAM(g_object_ref(g_io_stream_get_output_stream(stream)));
  return G_IO_STREAM(watched);
}

}  // namespace wircam::recorder
