#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Generate the reference CAN goniometer rig: its DBC, a candump -l log of a
seated-to-standing then arm-raise motion with faults, and the ground truth.

    python3 make_rig.py [OUTDIR]      (default: this script's folder)

Deterministic (fixed seed): running it again gives the same bytes. Python 3
standard library only.

The bus (500 kbit/s class, ~3.4 k frames/s):
  - 12 DBC goniometers 0x101..0x10C at 200 Hz (Intel and Motorola, signed,
    14- and 16-bit, one IEEE float), GenMsgCycleTime 5 ms;
  - RIG_STATUS 0x0F0 at 10 Hz, multiplexed (page 0: supply, temperature;
    page 1: node error bits, uptime; page 1 uses extended SG_MUL_VAL_ syntax);
  - 4 CANopen CiA 406 encoders, nodes 0x21..0x24 (TPDO1 0x1A1..0x1A4,
    position 0x6004 at 200 Hz, 4096 steps/rev), heartbeats 0x721..0x724
    every 100 ms;
  - a J1939 slope sensor on the head, source address 0x90, PGN 61459 at 100 Hz.
Faults (times relative to the first frame):
  5.00-5.50 s  KNEE_L (0x10B) silent;
  6.00-6.60 s  ANKLE_R (CANopen node 0x24) silent: TPDO and heartbeat; then
               boot-up heartbeat, NMT start from the master, operational;
  7.00 s       error frame: controller error-passive (rx errors 130);
  7.30 s       error frame: bus-off; nothing on the bus until
  7.40 s       error frame: controller restarted;
  8.00 s       a burst of 7 malformed log lines;
  8.50 s       one ELBOW_R frame with 2 data bytes instead of 8.
The truth file lists, every 50 ms, the value each channel's latest frame
carried (before quantisation), so a decoder can be checked to the
resolution of each signal, held values during faults included.
"""
import math
import os
import random
import struct
import sys

BASE_S = 1763769600  # 2025-11-22 00:00:00 UTC, seconds of the first frame
DURATION = 10.0
PERIOD = 0.005
STEPS = 4096


def smoothstep(a, b, t):
    x = min(max((t - a) / (b - a), 0.0), 1.0)
    return x * x * (3 - 2 * x)


def motion(t):
    """Joint angles in degrees at time t (template frames: +flexion)."""
    stand = smoothstep(1.0, 3.5, t)
    bump = math.sin(math.pi * stand)
    seated = 1.0 - stand
    raise_l = smoothstep(4.5, 6.5, t) - smoothstep(8.0, 9.5, t)
    raise_r = smoothstep(4.7, 6.7, t) - smoothstep(8.2, 9.7, t)
    return {
        "PELVIS.tilt": 20.0 * bump - 5.0 * seated,
        "LUMBAR.flex": 10.0 * seated + 20.0 * bump,
        "THORAX.flex": 5.0 * seated + 10.0 * bump,
        "NECK.flex": -10.0 * bump + 2.0 * math.sin(2 * math.pi * 0.25 * t),
        "SHOULDER_L.flex": 150.0 * raise_l,
        "SHOULDER_L.abd": 10.0 * raise_l,
        "SHOULDER_R.flex": 150.0 * raise_r,
        "SHOULDER_R.abd": 10.0 * raise_r,
        "ELBOW_L.flex": 20.0 + 30.0 * raise_l,
        "ELBOW_R.flex": 20.0 + 30.0 * raise_r,
        "HIP_L.flex": 90.0 * seated + 15.0 * bump,
        "HIP_R.flex": 90.0 * seated + 15.0 * bump,
        "KNEE_L.flex": 90.0 * seated,
        "KNEE_R.flex": 90.0 * seated,
        "WRIST_L.angle": -20.0 * math.sin(2 * math.pi * 0.5 * t) * raise_l,
        "WRIST_R.angle": -20.0 * math.sin(2 * math.pi * 0.5 * t) * raise_r,
        "ANKLE_L.angle": -15.0 * seated - 10.0 * bump,
        "ANKLE_R.angle": -15.0 * seated - 10.0 * bump,
        "HEAD.pitch": -5.0 * bump + 3.0 * math.sin(2 * math.pi * 0.3 * t),
        "HEAD.roll": 2.0 * math.sin(2 * math.pi * 0.2 * t),
    }


# DBC goniometers: id, name, byte order, layout of (signal, start, length, factor)
GONIO = [
    (0x101, "PELVIS", "float"),
    (0x102, "LUMBAR", "intel"),
    (0x103, "THORAX", "motorola"),
    (0x104, "NECK", "intel"),
    (0x105, "SHOULDER_L", "motorola2"),
    (0x106, "SHOULDER_R", "intel2"),
    (0x107, "ELBOW_L", "intel"),
    (0x108, "ELBOW_R", "motorola"),
    (0x109, "HIP_L", "motorola"),
    (0x10A, "HIP_R", "intel"),
    (0x10B, "KNEE_L", "intel14"),
    (0x10C, "KNEE_R", "motorola14"),
]
CANOPEN = [(0x21, "WRIST_L"), (0x22, "WRIST_R"), (0x23, "ANKLE_L"), (0x24, "ANKLE_R")]
HEAD_SA = 0x90
STATUS_ID = 0x0F0


def dbc_text():
    out = ['VERSION "pose goniometer rig 1"', "", "", "NS_ :", "\tCM_", "\tBA_DEF_", "\tBA_",
           "\tVAL_", "\tSIG_VALTYPE_", "\tSG_MUL_VAL_", "", "BS_:", "",
           "BU_: MASTER " + " ".join(n for _, n, _ in GONIO), "", ""]
    for mid, name, kind in GONIO:
        out.append(f"BO_ {mid} {name}: 8 {name}")
        if kind == "float":
            out.append(f' SG_ tilt : 0|32@1- (1,0) [-90|90] "deg" MASTER')
            out.append(f' SG_ seq : 32|8@1+ (1,0) [0|255] "" MASTER')
        elif kind in ("intel", "intel2"):
            out.append(f' SG_ flex : 0|16@1- (0.01,0) [-180|180] "deg" MASTER')
            second = "abd" if kind == "intel2" else "rate"
            unit, fac = ("deg", "0.01") if second == "abd" else ("deg/s", "0.1")
            out.append(f' SG_ {second} : 16|16@1- ({fac},0) [-1000|1000] "{unit}" MASTER')
            out.append(f' SG_ seq : 32|8@1+ (1,0) [0|255] "" MASTER')
        elif kind in ("motorola", "motorola2"):
            out.append(f' SG_ flex : 7|16@0- (0.01,0) [-180|180] "deg" MASTER')
            second = "abd" if kind == "motorola2" else "rate"
            unit, fac = ("deg", "0.01") if second == "abd" else ("deg/s", "0.1")
            out.append(f' SG_ {second} : 23|16@0- ({fac},0) [-1000|1000] "{unit}" MASTER')
            out.append(f' SG_ seq : 39|8@0+ (1,0) [0|255] "" MASTER')
        elif kind == "intel14":
            out.append(f' SG_ flex : 4|14@1- (0.02,0) [-10|160] "deg" MASTER')
            out.append(f' SG_ seq : 32|8@1+ (1,0) [0|255] "" MASTER')
        elif kind == "motorola14":
            out.append(f' SG_ flex : 5|14@0- (0.02,0) [-10|160] "deg" MASTER')
            out.append(f' SG_ seq : 39|8@0+ (1,0) [0|255] "" MASTER')
        out.append("")
    out.append(f"BO_ {STATUS_ID} RIG_STATUS: 8 MASTER")
    out.append(' SG_ page M : 0|4@1+ (1,0) [0|15] "" MASTER')
    out.append(' SG_ supply m0 : 8|16@1+ (0.001,0) [0|30] "V" MASTER')
    out.append(' SG_ temp m0 : 24|8@1- (1,0) [-40|125] "degC" MASTER')
    out.append(' SG_ node_errors m1 : 8|16@1+ (1,0) [0|65535] "" MASTER')
    out.append(' SG_ uptime m1 : 24|32@1+ (0.001,0) [0|4294967] "s" MASTER')
    out += ["", ""]
    out.append('CM_ "Reference goniometer rig of the pose project: 12 goniometers, '
               '4 CiA 406 encoders (not in this file: CANopen), 1 J1939 slope sensor.";')
    out.append('BA_DEF_ BO_ "GenMsgCycleTime" INT 0 65535;')
    out.append('BA_DEF_DEF_ "GenMsgCycleTime" 0;')
    for mid, _, _ in GONIO:
        out.append(f'BA_ "GenMsgCycleTime" BO_ {mid} 5;')
    out.append(f'BA_ "GenMsgCycleTime" BO_ {STATUS_ID} 100;')
    out.append(f'VAL_ {STATUS_ID} page 0 "power" 1 "diagnostics" ;')
    out.append(f"SIG_VALTYPE_ {0x101} tilt : 1;")
    out.append(f"SG_MUL_VAL_ {STATUS_ID} node_errors page 1-1;")
    out.append(f"SG_MUL_VAL_ {STATUS_ID} uptime page 1-1;")
    return "\n".join(out) + "\n"


def put_intel(buf, start, length, raw):
    raw &= (1 << length) - 1
    for i in range(length):
        if raw >> i & 1:
            bit = start + i
            buf[bit // 8] |= 1 << (bit % 8)


def put_motorola(buf, start, length, raw):
    raw &= (1 << length) - 1
    lin = start // 8 * 8 + (7 - start % 8)
    for i in range(length):  # i = 0 is the MSB
        if raw >> (length - 1 - i) & 1:
            b = lin + i
            buf[b // 8] |= 1 << (7 - b % 8)


def q(value, factor):
    return int(round(value / factor))


def gonio_frame(kind, name, ang, rate, seq):
    """Returns (data bytes, {channel: encoded physical value})."""
    b = bytearray(8)
    sent = {}
    if kind == "float":
        f = struct.unpack("<f", struct.pack("<f", ang["tilt"]))[0]
        b[0:4] = struct.pack("<f", f)
        b[4] = seq
        sent[name + ".tilt"] = ang["tilt"]
        return bytes(b), sent
    if kind in ("intel14", "motorola14"):
        raw = q(ang["flex"], 0.02)
        (put_intel if kind == "intel14" else put_motorola)(b, 4 if kind == "intel14" else 5, 14, raw)
        (put_intel if kind == "intel14" else put_motorola)(b, 32 if kind == "intel14" else 39, 8, seq)
        sent[name + ".flex"] = ang["flex"]
        return bytes(b), sent
    put = put_intel if kind.startswith("intel") else put_motorola
    s1, s2, s3 = (0, 16, 32) if kind.startswith("intel") else (7, 23, 39)
    put(b, s1, 16, q(ang["flex"], 0.01))
    sent[name + ".flex"] = ang["flex"]
    if kind.endswith("2"):
        put(b, s2, 16, q(ang["abd"], 0.01))
        sent[name + ".abd"] = ang["abd"]
    else:
        put(b, s2, 16, q(rate, 0.1))
        sent[name + ".rate"] = rate
    put(b, s3, 8, seq)
    return bytes(b), sent


def line(t, cid, data, ext=False, err=False):
    us = int(round(t * 1e6))
    stamp = f"({BASE_S + us // 1000000:010d}.{us % 1000000:06d})"
    if err:
        ident = f"{cid | 0x20000000:08X}"
    elif ext:
        ident = f"{cid:08X}"
    else:
        ident = f"{cid:03X}"
    return f"{stamp} can0 {ident}#{data.hex().upper()}"


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    rng = random.Random(20261122)
    events = []  # (t, order, text, {channel: value})

    def emit(t, text, sent=None):
        events.append((round(t, 6), len(events), text, sent or {}))

    def silent(name, node, t):
        if name == "KNEE_L" and 5.0 <= t < 5.5:
            return True
        if node == 0x24 and 6.0 <= t < 6.6:
            return True
        if 7.3 <= t < 7.4:  # bus-off: nothing gets through
            return True
        return False

    n_samples = int(round(DURATION / PERIOD))
    seq = 0
    prev = motion(0.0)
    for k in range(n_samples):
        t0 = k * PERIOD
        seq = (seq + 1) & 0xFF
        for i, (mid, name, kind) in enumerate(GONIO):
            t = t0 + i * 0.00015 + (rng.random() * 40e-6 if (k or i) else 0.0)
            if silent(name, 0, t):
                continue
            m = motion(t)
            noise = rng.gauss(0.0, 0.02)
            keys = {"PELVIS": ["tilt"], "SHOULDER_L": ["flex", "abd"], "SHOULDER_R": ["flex", "abd"]}
            ang = {}
            for s in keys.get(name, ["flex"]):
                ang[s] = m[f"{name}.{s}"] + noise
            rate = (m.get(name + ".flex", 0.0) - prev.get(name + ".flex", 0.0)) / PERIOD
            data, sent = gonio_frame(kind, name, ang, rate, seq)
            if name == "ELBOW_R" and k == int(8.5 / PERIOD):
                data = data[:2]  # the fault: a 2-byte frame
                sent = {name + ".flex": sent[name + ".flex"]}
            emit(t, line(t, mid, data), sent)
        for j, (node, name) in enumerate(CANOPEN):
            t = t0 + 0.0019 + j * 0.00015 + rng.random() * 40e-6
            if silent(name, node, t):
                continue
            a = motion(t)[name + ".angle"] + rng.gauss(0.0, 0.02)
            pos = int(round(a / 360.0 * STEPS)) % STEPS
            emit(t, line(t, 0x180 + node, struct.pack("<I", pos)), {name + ".angle": a})
        if k % 2 == 0:  # J1939 at 100 Hz
            t = t0 + 0.0027 + rng.random() * 40e-6
            if not silent("HEAD", 0, t):
                m = motion(t)
                p, r = m["HEAD.pitch"], m["HEAD.roll"]
                data = struct.pack("<HHH", int(round((p + 64) / 0.002)), int(round((r + 64) / 0.002)),
                                   0xFFFF) + bytes([0xFF, 0x00])
                ident = (3 << 26) | (61459 << 8) | HEAD_SA
                emit(t, line(t, ident, data, ext=True), {"HEAD.pitch": p, "HEAD.roll": r})
        if k % 20 == 0:  # 100 ms: heartbeats and rig status
            for j, (node, name) in enumerate(CANOPEN):
                t = t0 + 0.0031 + j * 0.0001
                if silent(name, node, t):
                    continue
                emit(t, line(t, 0x700 + node, bytes([0x05])))
            t = t0 + 0.0041
            if not silent("", 0, t):
                page = (k // 20) % 2
                b = bytearray(8)
                put_intel(b, 0, 4, page)
                if page == 0:
                    put_intel(b, 8, 16, q(12.05 + 0.01 * math.sin(t), 0.001))
                    put_intel(b, 24, 8, 31 + int(t // 4))
                else:
                    put_intel(b, 8, 16, 0x0400 if 5.0 <= t < 5.6 else 0)
                    put_intel(b, 24, 32, q(3600.0 + t, 0.001))
                emit(t, line(t, STATUS_ID, bytes(b)))
        prev = motion(t0)
    # ANKLE_R comes back: boot-up, NMT start from the master, operational heartbeats follow.
    emit(6.6001, line(6.6001, 0x724, bytes([0x00])))
    emit(6.6012, line(6.6012, 0x000, bytes([0x01, 0x24])))
    # Controller faults.
    emit(7.0002, line(7.0002, 0x004, bytes([0, 0x10, 0, 0, 0, 0, 8, 130]), err=True))
    emit(7.3, line(7.3, 0x040, bytes(8), err=True))
    emit(7.4, line(7.4, 0x100, bytes(8), err=True))
    # Garbage burst.
    garbage = [
        "(1763769608.000101) can0 1G3#0011",
        "this line is not a frame",
        "(1763769608.000203 can0 101#00",
        "(1763769608.000304) can0 101#0011223",
        "(1763769608.000405) can0 101#001122334455667788",
        "(abc.def) can0 101#00",
        "(1763769608.000506) can0 12345#00",
    ]
    for i, g in enumerate(garbage):
        emit(8.0001 + i * 1e-6, g)
    events.sort(key=lambda e: (e[0], e[1]))

    with open(os.path.join(outdir, "goniometer_rig.dbc"), "w", newline="\n") as f:
        f.write(dbc_text())
    with open(os.path.join(outdir, "sit_stand_arm_raise.log"), "w", newline="\n") as f:
        for e in events:
            f.write(e[2] + "\n")
    # Truth: latest encoded value per channel every 50 ms.
    channels = [f"{n}.{s}" for _, n, k in GONIO for s in
                (["tilt"] if k == "float" else ["flex", "abd"] if k.endswith("2") else ["flex"])]
    channels += [f"{n}.angle" for _, n in CANOPEN] + ["HEAD.pitch", "HEAD.roll"]
    latest = {}
    rows = []
    ei = 0
    for k in range(1, int(DURATION / 0.05) + 1):
        T = k * 0.05
        # compare in whole microseconds, as the log's stamps are written
        while ei < len(events) and int(round(events[ei][0] * 1e6)) <= k * 50000:
            latest.update(events[ei][3])
            ei += 1
        rows.append([f"{T:.3f}"] + [f"{latest[c]:.6f}" if c in latest else "" for c in channels])
    with open(os.path.join(outdir, "sit_stand_arm_raise_truth.csv"), "w", newline="\n") as f:
        f.write("t_s," + ",".join(channels) + "\n")
        for r in rows:
            f.write(",".join(r) + "\n")


if __name__ == "__main__":
    main()
