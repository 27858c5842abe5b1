#!/usr/bin/env python3
"""`epichead replay LOG --dbc DBC --csv` against an independent decoder, canmatrix (Debian
python3-canmatrix): every frame of the log whose id the DBC has is decoded by canmatrix, and
the CSV must hold exactly the same signals of the same frames with the same raw and physical
values. Signals that run beyond their message's length (a warning of the reader; canmatrix
decodes them from bits that are not in the frame) are left out of both.

    dbc_canmatrix_oracle.py EPICHEAD DBC LOG WORKDIR

Exit 0: they agree; 1: they do not (each difference printed); 77: canmatrix is not installed
(ctest counts the test skipped)."""
import csv
import re
import subprocess
import sys
from pathlib import Path

try:
    import canmatrix.formats
except ImportError:
    print("skipped: python3-canmatrix is not installed (apt-get install python3-canmatrix)")
    sys.exit(77)


def load_with_canmatrix(dbc_path, work):
    # canmatrix 0.9.5 refuses a 29-bit id written without bit 31 (the real anzen DBC writes
    # them so); the copy it reads has the flag set, which is how epichead reads those ids.
    text = Path(dbc_path).read_bytes().decode("latin-1")

    def flag(m):
        i = int(m.group(2))
        return m.group(1) + str(i | 0x80000000 if 0x7FF < i < 0x80000000 else i)

    text = re.sub(r"^(BO_ |CM_ BO_ |VAL_ |BA_ \"\w+\" BO_ |SIG_VALTYPE_ )(\d+)", flag, text, flags=re.M)
    fixed = Path(work) / "canmatrix_input.dbc"
    fixed.write_bytes(text.encode("latin-1"))
    dbs = canmatrix.formats.loadp(str(fixed))
    return dbs[""] if "" in dbs else next(iter(dbs.values()))


def fits(signal, size):
    # canmatrix's own bit positions: the LSB in Intel numbering (bit b = bit b % 8 of byte b / 8).
    lsb = signal.get_startbit(bit_numbering=1, start_little=True)
    top = lsb + signal.size - 1 if signal.is_little_endian else lsb
    return top // 8 < size


def main():
    epichead, dbc_path, log, work = sys.argv[1:5]
    Path(work).mkdir(parents=True, exist_ok=True)
    out_csv = Path(work) / "signals.csv"
    subprocess.run([epichead, "replay", log, "--dbc", dbc_path, "--csv", str(out_csv)], check=True,
                   stdout=subprocess.DEVNULL)
    db = load_with_canmatrix(dbc_path, work)
    frames = {(f.arbitration_id.id, f.arbitration_id.extended): f for f in db.frames}

    expected = []  # (t_s, message, signal, raw, physical)
    line_re = re.compile(r"^\((\d+\.\d+)\)\s+\S+\s+([0-9A-Fa-f]+)#([0-9A-Fa-f]*)\s*$")
    for line in Path(log).read_text().splitlines():
        m = line_re.match(line)
        if not m:
            continue
        t_s, can_id, data = m.group(1), m.group(2), bytes.fromhex(m.group(3))
        frame = frames.get((int(can_id, 16), len(can_id) == 8))
        if frame is None:
            continue
        for name, value in frame.decode(data).items():
            if fits(frame.signal_by_name(name), len(data)):
                expected.append((t_s, frame.name, name, int(value.raw_value), float(value.phys_value)))

    got = []
    with open(out_csv, newline="") as f:
        for row in csv.DictReader(f):
            got.append((row["t_s"], row["message"], row["signal"], int(row["raw"]), float(row["value"])))

    key = lambda r: (r[0], r[1], r[2])
    expected.sort(key=key)
    got.sort(key=key)
    problems = []
    if [key(r) for r in expected] != [key(r) for r in got]:
        e, g = set(map(key, expected)), set(map(key, got))
        problems.append(f"rows differ: {len(e - g)} only canmatrix decodes (e.g. {sorted(e - g)[:3]}), "
                        f"{len(g - e)} only epichead (e.g. {sorted(g - e)[:3]})")
    else:
        for e, g in zip(expected, got):
            if e[3] != g[3] or abs(e[4] - g[4]) > 1e-9 * max(1.0, abs(e[4])):
                problems.append(f"{e[0]} {e[1]}.{e[2]}: canmatrix raw {e[3]} value {e[4]}, epichead raw {g[3]} value {g[4]}")
    for p in problems[:20]:
        print(p)
    print(f"{len(expected)} signal values from canmatrix, {len(got)} from epichead, {len(problems)} differences")
    return 1 if problems or not expected else 0


if __name__ == "__main__":
    sys.exit(main())
