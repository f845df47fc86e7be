#!/usr/bin/env python3
"""Prints the AprilTags a WiRC camera sees: id, family, centre and corners in
pixels (and the pose when the tag size and focal length are given), read from
the WircTagMeta on each buffer through the Wirc typelib.

    python3 examples/follow_tags.py --host 127.0.0.1 --port 1984 --frames 30

Needs python3-gi and gir1.2-gstreamer-1.0; from a build tree also
GST_PLUGIN_PATH=build/gst-plugins GI_TYPELIB_PATH=build/lib/girepository-1.0
LD_LIBRARY_PATH=build/lib (an install or the .deb puts them where they are
found by themselves).
"""
import argparse
import sys

import gi

gi.require_version("Gst", "1.0")
gi.require_version("Wirc", "1.0")
from gi.repository import Gst, Wirc  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=1984)
    parser.add_argument("--camera", type=int, default=0)
    parser.add_argument("--frames", type=int, default=30, help="frames to read, then stop")
    parser.add_argument("--tag-size", type=float, default=0, help="metres, for the pose")
    parser.add_argument("--fx", type=float, default=0, help="focal length in pixels, for the pose")
    args = parser.parse_args()

    Gst.init(None)
    pose = f" tag-size={args.tag_size} fx={args.fx}" if args.tag_size and args.fx else ""
    pipeline = Gst.parse_launch(
        f"wircsrc host={args.host} port={args.port} camera={args.camera} ! tjpegdec ! "
        f"video/x-raw,format=GRAY8 ! apriltagdetect{pose} ! "
        "appsink name=sink max-buffers=4 drop=true sync=false")
    sink = pipeline.get_by_name("sink")
    pipeline.set_state(Gst.State.PLAYING)
    bus = pipeline.get_bus()
    seen = 0
    try:
        for frame in range(args.frames):
            sample = sink.emit("try-pull-sample", 5 * Gst.SECOND)
            if sample is None:
                error = bus.timed_pop_filtered(0, Gst.MessageType.ERROR)
                why = error.parse_error()[0].message if error else "no frame for 5 s"
                print(f"follow_tags: {why}", file=sys.stderr)
                return 1
            meta = Wirc.buffer_get_tag_meta(sample.get_buffer())
            for i in range(meta.get_n_tags() if meta else 0):
                tag = meta.get_tag(i)
                corners = [tag.get_corner(c)[1:] for c in range(4)]
                line = (f"frame {frame}: tag {tag.id} ({tag.get_family()}) at "
                        f"{tag.cx:.1f},{tag.cy:.1f} corners "
                        + " ".join(f"{x:.1f},{y:.1f}" for x, y in corners))
                if tag.has_pose:
                    line += f" pose x={tag.x:.2f} y={tag.y:.2f} z={tag.z:.2f} m"
                print(line, flush=True)
                seen += 1
    finally:
        pipeline.set_state(Gst.State.NULL)
    return 0 if seen else 1


if __name__ == "__main__":
    sys.exit(main())
