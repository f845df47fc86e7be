#include "sim_usage.h"

namespace wircam::sim {

const char* const kUsage = R"(Usage: wirc-sim [OPTIONS]

A WiRC device (protocol v1.3) on this machine: discovery on UDP, login and
control on TCP, PCD with failsafe, PSD, and MJPEG camera streams. The default
scene is a car whose camera follows an AprilTag target, driven by the PCD it
receives; --frames streams JPEG files instead.

Device:
  --port N             TCP control and UDP discovery port (default 1984;
                       0 = pick a free one). The port is printed on stdout.
  --bind ADDR          address to listen on (default 127.0.0.1)
  --name NAME          device name in BCSA (default wirc-sim)
  --serial SERIAL      serial number in BCSA, up to 7 characters (default SIM0001)
  --hw-version M.m     hardware version in BCSA (default 1.0)
  --sw-version M.m     software version in BCSA (default 1.3)
  --cameras N          number of cameras (default 1)
  --fps F              frames per second per camera (default 15)
  --size WxH           picture size (default 352x288, CIF)
  --quality Q          JPEG quality 1..100 (default 85)
  --fragment BYTES     payload bytes per UDP packet (default 64512, the device's)
  --pcd-timeout MS     failsafe after this long without PCD (default 800)
  --duration S         stop after S seconds (default: run until SIGINT/SIGTERM)

Scene:
  --scene follow|static  follow: the car drives by PCD (default);
                       static: the car stays put, the target still moves
  --clock-stamp        draw the wall clock's milliseconds (mod 2^32) as 32
                       black/white blocks across the top of each frame, most
                       significant first, for latency measurements
  --frames DIR         stream the .jpg/.jpeg files of DIR in name order,
                       byte for byte, looping (instead of a rendered scene)
  --replay PATH        replay a recorded drive as the live camera: PATH is a
                       wirc-recorder segment (.mkv of JPEG) or its folder (the
                       segments in index order); each frame byte for byte at
                       its recorded time, outages as outages (a pause over
                       10 s shortened to 10 s), the battery from the sidecars.
                       Stops at the end with a summary
  --camera NAME        the camera to replay from a folder holding several
  --speed X            replay X times as fast (default 1)
  --loop               replay again from the start at the end
  --commands-out FILE  write every PCD received with the frame on screen as
                       it came: JSON lines {"frame", "pts", "segment",
                       "channels", "arrival_ms"} (wirc-cli compare-commands)
  --family NAME        tag family (default tag36h11)
  --tags ID[,ID...]    tag ids; the first rides on the target (default 0)
  --tag-size M         tag edge (black border) in metres (default 0.16)
  --path still|line|circle  target path (default circle)
  --target-speed M/S   target speed (default 0.3)
  --start-distance M   camera to target at the start (default 1.2)
  --follow-distance M  set point the summary measures against (default 1.0)
  --control wirc|rcoip|btemp  what steers the car (default wirc: the PCD above).
                       rcoip: an RCOIP receiver (replies at most once a second,
                       to the sender only, fails safe after 2 s); btemp: a
                       BTEMP robot (answers PING, RCTR and CTRL, sends PINS).
                       The camera streams over WiRC MJPEG either way
  --control-port N     UDP port of that receiver or robot (default 9048 for
                       rcoip, 16980 for btemp; 0 = pick a free one, printed)
  --steering-channel N PCD channel steering the car, 1..8 (default 1; 2000 = left)
  --throttle-channel N PCD channel driving the car, 1..8 (default 2; 1500 = stop)
  --truth FILE         write the truth per frame as JSON lines

Marvelmind indoor positions:
  --marvelmind PORT    run a Marvelmind dashboard on UDP PORT (0 = pick a free
                       one, printed) reporting the scene's truth: the first
                       beacon rides on the car, the second on the target,
                       further ones stand still
  --marvelmind-beacons A[,B...]  beacon addresses, 1..254 (default 5)
  --marvelmind-rate HZ measurements per second (default 16)
  --marvelmind-noise M standard deviation of each coordinate (default 0.02 m)
  --marvelmind-dropout P  probability a measurement is missed (default 0)
  --marvelmind-push HOST:PORT  also push each measurement there (stream mode)
  --marvelmind-push-units cm|mm  what the pushes carry (default cm)
  --marvelmind-timestamp 64|ms  timestamp unit: 1/64 s as the protocol text
                       says (default), or ms as newer dashboards

Impairments of the video stream (all seeded by --seed, repeatable):
  --loss P             probability a packet is lost (0..1)
  --burst-loss P       probability a loss burst starts at a packet
  --burst-length N     packets lost per burst (default 5)
  --duplicate P        probability a packet is sent twice
  --reorder N          hold N packets back and release them in random order
  --jitter BYTES       vary the fragment size by up to +-BYTES
  --start-frame N      first frame number (e.g. 4294967290 to test wrap-around)
  --reserved-bits      set the version's reserved bits 31..17
  --stray P            per frame, probability of a forged packet from another port
  --misdirect PORT     stream to this port of the receiver instead of the one it
                       asked for (a NAT or firewall that maps it wrong)
  --seed N             random seed (default 1)

  -h, --help           show this text

On exit (SIGINT, SIGTERM or --duration) it prints a summary: frames sent, PCD
received, the longest PCD gap, failsafe entries, and how well the car followed.
)";

}  // namespace wircam::sim
