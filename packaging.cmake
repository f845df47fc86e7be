# `cpack -G DEB` in the build folder: a .deb that `apt install ./wircam_*.deb`
# installs onto Debian 12 with its dependencies (shared-library ones found
# by dpkg-shlibdeps, the GStreamer elements the recorder plugs by name
# listed here).
set(CPACK_PACKAGE_NAME wircam)
set(CPACK_PACKAGE_VENDOR "wircam")
set(CPACK_PACKAGE_CONTACT "wircam developers <wircam@users.noreply.github.com>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "WiRC-class vehicle cameras in GStreamer: source, AprilTag following, recorder")
set(CPACK_PACKAGE_DESCRIPTION
    "GStreamer plugins (wircsrc, wircdepay, wirccontrol, marvelmindpositions, tjpegdec,
 apriltagdetect, tagoverlay), the wirc-recorder service with its systemd unit,
 wirc-cli, wirc-sim, and libwircam-gst with its typelib for Python.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
# The unit's paths are written at install time: the staging must keep /usr.
set(CPACK_SET_DESTDIR ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_STRIP_FILES ON)  # the debug info stays in the build tree
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
# Elements plugged by name: matroskamux, splitmuxsink, jpegdec (good),
# videoconvert, appsrc/appsink (base); Python reads the metas with these.
# libmosquitto1 is opened by wirc-recorder at run time (--mqtt), so
# dpkg-shlibdeps cannot see it.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "gstreamer1.0-plugins-base, gstreamer1.0-plugins-good, gir1.2-gstreamer-1.0, libmosquitto1")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "gstreamer1.0-plugins-ugly, gstreamer1.0-tools, python3-gi, mosquitto, ffmpeg")
include(CPack)
