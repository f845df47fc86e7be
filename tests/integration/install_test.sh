#!/usr/bin/env bash
# `cmake --install` into a temporary prefix, then used from there the way a
# user would: the plugins with gst-inspect-1.0, the tools, the library
# through pkg-config from C, and the typelib from Python.
#   install_test.sh BUILD_DIR
set -euo pipefail
build=$(realpath "$1")
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
multiarch=$(gcc -print-multiarch)
lib="$prefix/lib/$multiarch"

cmake --install "$build" --prefix "$prefix" >/dev/null
# Nothing outside the prefix.
outside=$(grep -v "^$prefix/" "$build/install_manifest.txt" || true)
[[ -z "$outside" ]] || { echo "installed outside the prefix: $outside" >&2; exit 1; }
for file in bin/wirc-recorder bin/wirc-cli bin/wirc-sim include/wircam/wirc_tag_meta.h \
            include/wircam/wirc_position_meta.h lib/systemd/system/wirc-recorder.service \
            "lib/$multiarch/gstreamer-1.0/libgstwirc.so" \
            "lib/$multiarch/gstreamer-1.0/libgstwircvision.so" \
            "lib/$multiarch/libwircam-gst.so.0" "lib/$multiarch/pkgconfig/wircam-gst.pc" \
            "lib/$multiarch/wircam/wirc-recorder-servers.so" \
            "lib/$multiarch/girepository-1.0/Wirc-1.0.typelib" share/gir-1.0/Wirc-1.0.gir; do
  [[ -e "$prefix/$file" ]] || { echo "missing: $prefix/$file" >&2; exit 1; }
done
grep -q "^ExecStart=$prefix/bin/wirc-recorder " "$prefix/lib/systemd/system/wirc-recorder.service"

# The installed plugins load (libwircam-gst found through their RPATH), and
# they are the ones under the prefix, not the build tree's.
export GST_REGISTRY="$prefix/registry.bin"
export GST_PLUGIN_PATH="$lib/gstreamer-1.0"
for element in wircsrc wircdepay wirccontrol marvelmindpositions tjpegdec apriltagdetect tagoverlay; do
  details=$(gst-inspect-1.0 "$element")
  grep -q "Filename.*$lib/gstreamer-1.0/" <<<"$details" ||
    { echo "gst-inspect-1.0 $element did not load it from $lib" >&2; exit 1; }
done
grep -q "Usage: wirc-cli" <<<"$("$prefix/bin/wirc-cli" --help)"
grep -q "Usage: wirc-recorder" <<<"$("$prefix/bin/wirc-recorder" --help 2>&1)"
# The installed recorder finds its web server's module (lib/<multiarch>/wircam/).
served=$("$prefix/bin/wirc-recorder" --device 127.0.0.1:9 --out "$prefix/recordings" \
         --http 127.0.0.1:0 --duration 1 2>&1 || true)
grep -q "live view at http://127.0.0.1:" <<<"$served" ||
  { echo "the installed wirc-recorder did not start its web server: $served" >&2; exit 1; }

# C through pkg-config: a tag meta added and read back.
cat >"$prefix/meta.c" <<'C'
#include <wirc_tag_meta.h>
int main(void) {
  gst_init(NULL, NULL);
  GstBuffer* buffer = gst_buffer_new();
  WircTagMeta* meta = gst_buffer_add_wirc_tag_meta(buffer, 352, 288);
  WircTag tag = {.id = 7, .family = "tag36h11", .cx = 10, .cy = 20};
  g_array_append_val(meta->tags, tag);
  WircTagMeta* read = wirc_buffer_get_tag_meta(buffer);
  int ok = read && wirc_tag_meta_get_n_tags(read) == 1 && wirc_tag_meta_get_tag(read, 0)->id == 7;
  gst_buffer_unref(buffer);
  return ok ? 0 : 1;
}
C
export PKG_CONFIG_PATH="$lib/pkgconfig"
cc "$prefix/meta.c" -o "$prefix/meta" $(pkg-config --cflags --libs wircam-gst) -Wl,-rpath,"$lib"
"$prefix/meta"

# Python through the typelib.
GI_TYPELIB_PATH="$lib/girepository-1.0" LD_LIBRARY_PATH="$lib" /usr/bin/python3 - <<'PY'
import gi
gi.require_version("Gst", "1.0")
gi.require_version("Wirc", "1.0")
from gi.repository import Gst, Wirc
Gst.init(None)
assert Wirc.buffer_get_tag_meta(Gst.Buffer.new()) is None
assert Wirc.buffer_get_n_position_metas(Gst.Buffer.new()) == 0
PY
echo "installed into $prefix and used from there"
