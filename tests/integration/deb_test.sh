#!/usr/bin/env bash
# `cpack -G DEB` makes a .deb with everything under /usr, the systemd unit
# pointing at /usr/bin, and the dependencies apt needs to pull.
#   deb_test.sh BUILD_DIR
set -euo pipefail
build=$(realpath "$1")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
(cd "$build" && cpack -G DEB -B "$out" >/dev/null)
deb=$(ls "$out"/wircam_*.deb)
multiarch=$(gcc -print-multiarch)
contents=$(dpkg-deb -c "$deb")
echo "$contents" | awk '{print $6}'
for file in ./usr/bin/wirc-recorder ./usr/bin/wirc-cli ./usr/bin/wirc-sim \
            "./usr/lib/$multiarch/gstreamer-1.0/libgstwirc.so" \
            "./usr/lib/$multiarch/gstreamer-1.0/libgstwircvision.so" \
            "./usr/lib/$multiarch/libwircam-gst.so.0" \
            "./usr/lib/$multiarch/wircam/wirc-recorder-servers.so" \
            "./usr/lib/$multiarch/girepository-1.0/Wirc-1.0.typelib" \
            ./usr/lib/systemd/system/wirc-recorder.service ./usr/include/wircam/wirc_tag_meta.h; do
  grep -qE " $file( ->|\$)" <<<"$contents" || { echo "the .deb lacks $file" >&2; exit 1; }
done
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
# libsoup and the RTSP server only through the servers' module (loaded at
# run time, but a file of the package that dpkg-shlibdeps reads).
for package in libgstreamer1.0-0 libturbojpeg0 libapriltag3 gstreamer1.0-plugins-good libmosquitto1 \
               libsoup-3.0-0 libgstrtspserver-1.0-0; do
  grep -q "$package" <<<"$depends" || { echo "Depends lacks $package" >&2; exit 1; }
done
dpkg-deb -x "$deb" "$out/root"
grep -q "^ExecStart=/usr/bin/wirc-recorder " "$out/root/usr/lib/systemd/system/wirc-recorder.service"
echo "built $(basename "$deb")"
