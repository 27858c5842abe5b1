#!/usr/bin/env python3
"""Writes the seed inputs of the fuzz targets into a folder per target (default:
build-fuzz/seeds/<target>/), from the real files (../shared/data, tests/data, sim/scenarios,
sim/scenes) and a few frames built here. ./dev fuzz starts each campaign from the committed
corpus plus these seeds; --merge keeps only the inputs that add coverage."""
import math
import os
import struct
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SHARED = (ROOT / ".." / "shared" / "data").resolve()


def write(out, target, name, data):
    d = out / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


def cao(out):
    for p in sorted((ROOT / "tests/data/cao").glob("*.cao")) + sorted((ROOT / "sim/scenes").glob("*.cao")):
        if p.stat().st_size < 64 * 1024:
            write(out, "cao_model", p.stem, p.read_bytes())
    write(out, "cao_model", "teabox", (SHARED / "teabox/model.cao").read_bytes())
    # include_main.cao with its includes as inc1.cao (cube) and sub/inc2.cao (triangle).
    main = (ROOT / "tests/data/cao/include_main.cao").read_text()
    main = main.replace('"cube.cao"', '"inc1.cao"').replace('"include/triangle.cao"', '"sub/inc2.cao"')
    cube = (ROOT / "tests/data/cao/cube.cao").read_text()
    tri = (ROOT / "tests/data/cao/include/triangle.cao").read_text()
    write(out, "cao_model", "include_split", main + "@@file@@\n" + cube + "@@file@@\n" + tri)
    write(out, "cao_model", "include_cycle", 'V1\nload("inc1.cao")\n0\n0\n0\n0\n0\n0\n@@file@@\nV1\nload("main.cao")\n0\n0\n0\n0\n0\n0\n')


def camera(out):
    for p in [ROOT / "tests/data/seq/camera.yaml", SHARED / "teabox/camera.yaml", SHARED / "teabox_left/camera.yaml"]:
        write(out, "camera_yaml", p.parent.name, p.read_bytes())
    # As a cv::fisheye calibration is saved: fisheye_model: 1 and k1..k4.
    write(out, "camera_yaml", "fisheye",
          "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nfisheye_model: 1\n"
          "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
          "   data: [ 210., 0., 318.5, 0., 212., 241.25, 0., 0., 1. ]\n"
          "distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: d\n"
          "   data: [ 0.08, -0.03, 0.01, -0.002 ]\n")
    # As ROS's camera_calibration writes camera_info: plain YAML, no directive, no dt.
    write(out, "camera_yaml", "ros_camera_info",
          "image_width: 640\nimage_height: 480\ncamera_name: head_camera\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
          "  data: [500.0, 0.0, 320.5, 0.0, 505.0, 240.25, 0.0, 0.0, 1.0]\ndistortion_model: plumb_bob\n"
          "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.1, 0.01, 0.001, 0.002, 0.0005]\n")
    # ROS's rational_polynomial: k1 k2 p1 p2 k3 k4 k5 k6.
    write(out, "camera_yaml", "ros_rational",
          "image_width: 640\nimage_height: 480\ncamera_name: head_camera\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
          "  data: [520.0, 0.0, 318.25, 0.0, 523.5, 243.5, 0.0, 0.0, 1.0]\ndistortion_model: rational_polynomial\n"
          "distortion_coefficients:\n  rows: 1\n  cols: 8\n"
          "  data: [0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082]\n")
    # OpenCV's rational (8), thin-prism (12) and tilted (14) models, as its calibration sample
    # writes them: a column of coefficients.
    coefficients = [0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082, 0.0021, -0.0004, -0.0015, 0.0003, 0.012, -0.021]
    for n in (8, 12, 14):
        write(out, "camera_yaml", f"opencv_k{n}",
              "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nflags: 16384\n"
              "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
              "   data: [ 520., 0., 318.25, 0., 523.5, 243.5, 0., 0., 1. ]\n"
              f"distortion_coefficients: !!opencv-matrix\n   rows: {n}\n   cols: 1\n   dt: d\n"
              "   data: [ " + ", ".join(repr(c) for c in coefficients[:n]) + " ]\n")


def csvs(out):
    init = (SHARED / "teabox/init.csv").read_text()
    gt = "".join((SHARED / "teabox/reference_visp.csv").read_text().splitlines(True)[:6])
    write(out, "sequence_csv", "init", "i" + init)
    write(out, "sequence_csv", "gt", "g" + gt)
    write(out, "sequence_csv", "gt_status", "g" + gt.splitlines()[0] + ",status\n" +
          "".join(l + ",tracked\n" for l in gt.splitlines()[1:]))
    write(out, "sequence_csv", "imu", "ut_s,gx,gy,gz,ax,ay,az\n0,0.01,-0.02,0.5,0.1,-9.81,0.2\n"
          "0.005,0.011,-0.021,0.49,0.12,-9.8,0.19\n0.01,1e-3,2.5e-4,-0.5,0,-9.79,0\n")
    write(out, "sequence_csv", "frames", "fframe,t_s,file\n0,0.2,frames/000000.png\n1,0.2333333333333333,frames/000001.png\n")
    write(out, "sequence_csv", "frames_video", "fframe,t_s,file\n0,0,\n1,0.04,\n2,0.08,\n")
    write(out, "sequence_csv", "covariance", "cframe,t_s,c_tx_tx,c_tx_ty,c_tx_tz,c_tx_rx,c_tx_ry,c_tx_rz,c_ty_ty,c_ty_tz,c_ty_rx,c_ty_ry,c_ty_rz,c_tz_tz,c_tz_rx,c_tz_ry,c_tz_rz,c_rx_rx,c_rx_ry,c_rx_rz,c_ry_ry,c_ry_rz,c_rz_rz\n0,0,1e-06,2e-07,2e-07,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,1e-06,2e-07,1e-06\n3,0.1,1e-06,2e-07,2e-07,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,2e-07,1e-06,2e-07,2e-07,1e-06,2e-07,1e-06\n")


def candump(out):
    logs = sorted((SHARED / "can").glob("*.log")) + sorted((SHARED / "can").glob("*.txt"))
    lines = set()
    for p in logs:
        text = p.read_bytes()
        # The reader: small logs whole, the first 4 KiB of large ones.
        write(out, "candump_reader", p.stem, text if len(text) <= 4096 else text[: text.rfind(b"\n", 0, 4096) + 1])
        seen_shapes = set()
        for line in text.splitlines():
            # One line per shape (length of the data field, FD, remote, error, default format).
            shape = (len(line.split(b"#")[-1]) if b"#" in line else len(line), b"##" in line, b"R" in line[-3:])
            if shape not in seen_shapes and len(seen_shapes) < 12:
                seen_shapes.add(shape)
                lines.add(line)
    extra = [b"(1436509052.249713) can0 123#R", b"(1436509052.249713) can0 123#R4",
             b"(1436509052.249713) can0 20000004#0004000000000000", b"(1436509052.249713) can0 123##1DEADBEEF",
             b"(1436509052.249713) can0 123#11.22.33", b"(1436509052.249713) can0 123#1122334455667788_C",
             b"(1436509052.249713) can0 123#DEADBEEF R", b"  can0  123   [2]  remote request",
             b"(1436509052.249713)  can0  680   [8]  03 22 01 00 00 00 00 00", b"# comment",
             b"(1.000000) vcan1 1F334455##3" + b"AB" * 64 + b" T"]
    lines.update(extra)
    for i, line in enumerate(sorted(lines)):
        write(out, "candump_line", f"line{i:02d}", line)
    write(out, "candump_reader", "mixed", b"\n".join(extra) + b"\r\nbad line\n\n")


def can_protocol(out):
    def frame(can_id, payload, flags=0):
        return bytes([flags]) + struct.pack("<I", can_id) + bytes([len(payload)]) + bytes(payload)
    seeds = {
        "time_sync_request": frame(0x080, [7, 0, 1, 2, 3, 4, 5, 6]),
        "time_sync_reply": frame(0x082, [7, 0, 9, 8, 7, 6, 5, 4]),
        "head_command": frame(0x100, [0x13, 0x10, 0x27, 0xF0, 0xD8, 0x14, 0x00, 0x00]),
        "imu_gyro": frame(0x110, [1, 0, 0xFF, 0xFF, 0, 0x80, 0x35, 0x12]),
        "imu_accel": frame(0x111, [0, 0x40, 0, 0, 0xFF, 0x7F, 0x35, 0x12]),
        "head_state": frame(0x120, [0x21, 0, 0, 0, 0, 0, 0, 0]),
        "head_status": frame(0x121, [0xE8, 0x03, 0x18, 0xFC, 0x05, 0x00, 0x09, 0x28]),
        "heartbeat": frame(0x702, [1, 1, 0, 3, 1, 0x10, 0x0E, 0x00]),
        "short": frame(0x110, [1, 2, 3]),
        "extended": frame(0x110, [0] * 8, flags=1),
    }
    for name, data in seeds.items():
        write(out, "can_protocol", name, data)


def half(x):
    return struct.unpack("<H", struct.pack("<e", x))[0]


def crc16(signature, payload):
    crc = 0xFFFF
    for b in list(struct.pack("<Q", signature)) + list(payload):
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def raw_imu_frames(node, tid, covariance=0, priority=16):
    payload = (123456789).to_bytes(7, "little") + struct.pack("<f", 0.005)
    payload += b"".join(struct.pack("<H", half(v)) for v in (0.1, -0.2, 0.3))
    payload += struct.pack("<3f", 0.0005, -0.001, 0.0015)
    payload += b"".join(struct.pack("<H", half(v)) for v in (0.5, 0.0, -9.81))
    payload += struct.pack("<3f", 0.0025, 0.0, -0.049)
    payload += b"\x00\x3c" * covariance
    stream = struct.pack("<H", crc16(0x8280632C40E574B5, payload)) + payload
    can_id = (priority << 24) | (1003 << 8) | node
    frames = []
    toggle = 0
    for at in range(0, len(stream), 7):
        chunk = stream[at:at + 7]
        tail = (0x80 if at == 0 else 0) | (0x40 if at + 7 >= len(stream) else 0) | (0x20 if toggle else 0) | tid
        frames.append((can_id, chunk + bytes([tail])))
        toggle ^= 1
    return frames


def dronecan(out):
    def record(step_ms, can_id, data, flags=1):
        return struct.pack("<h", step_ms) + bytes([flags]) + struct.pack("<I", can_id) + bytes([len(data)]) + data
    write(out, "dronecan_raw_imu", "one", b"".join(record(0, i, d) for i, d in raw_imu_frames(10, 3)))
    write(out, "dronecan_raw_imu", "covariance", b"".join(record(0, i, d) for i, d in raw_imu_frames(10, 4, 9)))
    a, b = raw_imu_frames(10, 5), raw_imu_frames(11, 6)
    inter = [x for pair in zip(a, b) for x in pair]
    write(out, "dronecan_raw_imu", "two_nodes", b"".join(record(1, i, d) for i, d in inter))
    write(out, "dronecan_raw_imu", "timeout", b"".join(record(3000 if k == 3 else 1, i, d)
                                                        for k, (i, d) in enumerate(raw_imu_frames(12, 7))))


def hid(out):
    def report(counter, stamp, gyro, accel):
        return bytes([1, counter]) + struct.pack("<I", stamp) + struct.pack("<3h", *gyro) + struct.pack("<3h", *accel)
    write(out, "hid_imu_report", "zero", report(0, 0, (0, 0, 0), (0, 0, 0)))
    write(out, "hid_imu_report", "sample", report(17, 123456, (100, -200, 32767), (-32768, 2048, 0)))
    write(out, "hid_imu_report", "padded", report(255, 0xFFFFFFFF, (1, 2, 3), (4, 5, 6)) + bytes(46))


def scenario(out):
    for p in sorted((ROOT / "sim/scenarios").glob("*.scn")):
        write(out, "scenario", p.stem, p.read_bytes())


RUN_CONFIG_EVERY_KEY = """{ "model": "m.cao", "camera_calibration": "c.yaml", "init_pose": "i.csv", "template_cache": "t",
  "reacquire": true, "mode": "hold", "out": "o",
  "camera": { "device": "/dev/video1", "width": 1280, "height": 720, "fps": 30 },
  "can": { "interface": "vcan0", "receive_buffer_bytes": 0, "time_sync_max_round_trip_ms": 45 },
  "head": { "pan_backlash_rad": 0.002, "tilt_backlash_rad": 0.001 },
  "threads": { "control_cpu": 1, "vision_cpu": 0, "control_priority": 80, "vision_priority": 10, "lock_memory": true },
  "controller": { "stabilise_gain_per_s": 60, "fixate_gain_per_s": 5, "fixate_max_rate_radps": 1.5,
                  "target_rate_filter_s": 0.15, "target_rate_max_radps": 1, "hold_gain_per_s": 10,
                  "hold_max_rate_radps": 2, "rate_lead_s": 0.006, "rate_lead_filter_s": 0.004 } }
"""


def run_config(out):
    write(out, "run_config", "full", """{ "model": "teabox/model.cao", "camera_calibration": "teabox/camera.yaml",
  "init_pose": "teabox/init.csv",
  "camera": { "device": "/dev/video0", "width": 640, "height": 480, "fps": 0 },
  "can": { "interface": "can0" },
  "head": { "pan_backlash_rad": 0.002, "tilt_backlash_rad": 0 },
  "mode": "fixate", "out": "run-out" }
""")
    write(out, "run_config", "minimal", '{"model":"m.cao","camera_calibration":"/abs/c.yaml","init_pose":"i.csv"}')
    write(out, "run_config", "detect", '{"model":"m.cao","camera_calibration":"c.yaml","reacquire":false,"template_cache":"t"}')
    # Every key docs/run_config.md lists, and misspelt keys (an error naming the key).
    write(out, "run_config", "every_key", RUN_CONFIG_EVERY_KEY)
    write(out, "run_config", "unknown_key", '{"model":"m.cao","camera_calibration":"c.yaml","camera":{"widht":1280}}')
    write(out, "run_config", "unknown_top_key", '{"model":"m.cao","camera_calibration":"c.yaml","reaquire":false}')


def template_record(view, roll, dist, distance_m, dx, dy, levels):
    b = struct.pack("<iiifffB", view, roll, dist, distance_m, dx, dy, len(levels))
    for level, (w, h, feats) in enumerate(levels):
        b += struct.pack("<iiiI", w, h, level, len(feats))
        for x, y, label in feats:
            b += struct.pack("<hhB", x, y, label)
    return b


def template_cache(out):
    # vision/src/template_cache.h's layout: a real cache is megabytes; these hold its every part.
    def cache(key, records):
        return b"EPHDTPL1" + struct.pack("<QI", key, len(records)) + b"".join(records)
    r1 = template_record(3, 5, 1, 0.45, 12.5, -3.0, [(60, 40, [(k * 3, k * 2, k % 8) for k in range(10)]),
                                                       (30, 20, [(k, k, k % 8) for k in range(5)])])
    r2 = template_record(160, 23, 7, 1.25, 40.0, 33.0, [(20, 20, [(0, 0, 0), (20, 20, 7)])])
    write(out, "template_cache", "two_templates", cache(0x1234, [r1, r2]))
    write(out, "template_cache", "one_template", cache(7, [r2]))
    write(out, "template_cache", "truncated", cache(7, [r1])[:-5])


def dbc(out):
    # The real databases whole (ours and the third-party one), each with a frame to decode,
    # and small ones for what neither has: FD, signed Motorola, floats, VAL_, cycle times.
    frame = b"\n@@frame@@\n"
    ours = (ROOT / "firmware_iface/epichead.dbc").read_bytes()
    anzen = (SHARED / "can/canbus_visualizer_anzen.dbc").read_bytes()
    write(out, "dbc", "epichead", ours + frame + bytes([0x13, 0x10, 0x27, 0xF0, 0xD8, 0x14, 0x00, 0x00]))
    write(out, "dbc", "anzen", anzen + frame + bytes.fromhex("4139E9391A444540") + frame + bytes.fromhex("0101020304050607"))
    small = ('VERSION ""\n\nNS_ :\n\tCM_\n\tBA_\n\nBS_:\n\nBU_: N\n\n'
             'BO_ 2147483905 Fd: 64 N\n SG_ sel M : 0|8@1+ (1,0) [0|3] "" N\n'
             ' SG_ a m1 : 7|12@0- (0.5,1) [-1000|1000] "x" N\n SG_ f m2 : 32|32@1- (2,0) [0|0] "" N\n'
             ' SG_ last : 504|8@1+ (1,0) [0|0] "\xb0C" N\n\n'
             'BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n SG_ o : 0|8@1+ (1,0) [0|0] "" X\n\n'
             'CM_ BO_ 2147483905 "a; b\nc";\nBA_DEF_DEF_ "GenMsgCycleTime" 50;\n'
             'BA_ "GenMsgCycleTime" BO_ 2147483905 10;\nVAL_ 2147483905 sel 0 "Off" 1 "On" ;\n'
             'SIG_VALTYPE_ 2147483905 f : 1;\n').encode("latin-1")
    write(out, "dbc", "small_fd", small + frame + bytes(range(64)) + frame + bytes([2, 0, 0, 0, 0, 0, 0xC0, 0x3F]))
    write(out, "dbc", "truncated_sg", b'BO_ 256 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|')
    write(out, "dbc", "bad_order", b'BO_ 256 M: 8 N\n SG_ a : 0|8@2+ (1,0) [0|0] "" N\n')
    write(out, "dbc", "beyond_frame", b'BO_ 256 M: 8 N\n SG_ a : 60|8@1+ (1,0) [0|0] "" N\n' + frame + bytes(9))


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build-fuzz" / "seeds"
    for make in (cao, camera, csvs, candump, can_protocol, dronecan, hid, scenario, run_config, template_cache, dbc):
        make(out)


if __name__ == "__main__":
    main()
