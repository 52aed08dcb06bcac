#!/usr/bin/python3
"""Mutation campaign over lacuna's volume readers (issue 15; docs/reliability.md, "Readers").

Generates small valid volumes with `lacuna generate` in every format, derives malformed inputs
from them (bit flips, byte stomps, truncations, appended junk, huge or negative dims, damaged
lengths and offsets, header-line edits, detached data files pointing at devices or outside the
folder, devices, FIFOs and duplicates in DICOM folders), and runs `lacuna info` and
`lacuna render` on each with a timeout. Every run must end in one of two ways:

  exit 0                       the input was still a valid volume;
  exit 2, one line on stderr   an error, and no output file, no temporary left behind.

and in both cases the input files must be unchanged. Anything else is a violation: a signal
(crash), a timeout (hang), another exit code, a multi-line or empty error, output written on
failure, or a modified input. Violating cases are kept under --keep for reproduction.

Usage:
  bench/mutate_campaign.py --lacuna build/lacuna --count 5000        # the benchmark run
  bench/mutate_campaign.py --lacuna build/lacuna --count 100 --smoke  # the ctest (quick)

Python standard library only. Exit code: 0 when no run violated the contract, 1 otherwise.
"""

import argparse
import gzip
import hashlib
import json
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

DIMS = "12x10x8"

# Base inputs: (name, generate kind, voxel type, output name). Detached formats write a
# companion .raw; DICOM writes a folder.
BASES = [
    ("nii_u8", "sphere", "uint8", "v.nii"),
    ("nii_i16", "tree", "int16", "v.nii"),
    ("nii_f32", "sphere", "float32", "v.nii"),
    ("niigz_i16", "sphere", "int16", "v.nii.gz"),
    ("niigz_u16", "tree", "uint16", "v.nii.gz"),
    ("nrrd_u8", "sphere", "uint8", "v.nrrd"),
    ("nrrd_f32", "tree", "float32", "v.nrrd"),
    ("nhdr_i16", "sphere", "int16", "v.nhdr"),
    ("mha_u16", "sphere", "uint16", "v.mha"),
    ("mha_f32", "tree", "float32", "v.mha"),
    ("mhd_u8", "tree", "uint8", "v.mhd"),
    ("raw_i16", "sphere", "int16", "v_12x10x8_int16.raw"),
    ("dicom_i16", "sphere", "int16", "series/"),
    ("dicom_u8", "tree", "uint8", "series/"),
]


def sha(path):
    """Hash of a file, or of every file below a folder (names and bytes; links by target)."""
    h = hashlib.sha256()
    if os.path.isdir(path) and not os.path.islink(path):
        for root, dirs, files in sorted(os.walk(path)):
            dirs.sort()
            for f in sorted(files):
                p = os.path.join(root, f)
                h.update(os.path.relpath(p, path).encode())
                if os.path.islink(p):
                    h.update(b"->" + os.readlink(p).encode())
                elif os.path.isfile(p):
                    with open(p, "rb") as fh:
                        h.update(fh.read())
    elif os.path.islink(path):
        h.update(b"->" + os.readlink(path).encode())
    elif os.path.isfile(path):
        with open(path, "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()


# ---------------------------------------------------------------------------------------------
# Mutators. Each takes (rng, bytes) and returns new bytes; the "file" ones act on a case folder.

def flip_bits(rng, b):
    b = bytearray(b)
    if not b:
        return bytes(b)
    limit = min(len(b), 1024) if rng.random() < 0.7 else len(b)  # headers live up front
    for _ in range(rng.randint(1, 8)):
        i = rng.randrange(limit)
        b[i] ^= 1 << rng.randrange(8)
    return bytes(b)


def stomp_bytes(rng, b):
    b = bytearray(b)
    if not b:
        return bytes(b)
    limit = min(len(b), 600)
    for _ in range(rng.randint(1, 4)):
        i = rng.randrange(limit)
        v = rng.choice([b"\x00", b"\xff", b"\x7f", b"\x80", b"\xff\xff\xff\x7f", b"\x00\x00\x00\x80",
                        b"\xff\xff\xff\xff"])
        b[i:i + len(v)] = v
    return bytes(b[:len(b)])


def truncate(rng, b):
    if len(b) < 2:
        return b""
    cut = rng.choice([rng.randrange(len(b)), rng.randrange(min(len(b), 400)), len(b) - 1, 0, 4, 347])
    return b[:min(cut, len(b))]


def append_junk(rng, b):
    return b + bytes(rng.randrange(256) for _ in range(rng.randint(1, 300)))


INT_EDITS = ["0", "-1", "1", "2", "-32768", "32767", "32768", "30000", "65535", "100000",
             "2147483647", "-2147483648", "4294967296", "9223372036854775807",
             "18446744073709551615", "1e40", "nan", "-0", "3.5", ""]


def edit_text_numbers(rng, b):
    """Replaces numbers in the text header (before the data) with edge values."""
    head_end = b.find(b"\n\n")
    if head_end < 0:
        m = re.search(rb"ElementDataFile[^\n]*\n", b)
        head_end = m.end() if m else min(len(b), 2000)
    head, rest = b[:head_end], b[head_end:]
    nums = list(re.finditer(rb"-?\d+(\.\d+)?", head))
    if not nums:
        return flip_bits(rng, b)
    m = rng.choice(nums)
    head = head[:m.start()] + rng.choice(INT_EDITS).encode() + head[m.end():]
    return head + rest


def edit_text_lines(rng, b):
    """Deletes, duplicates or rewrites one header line."""
    head_end = b.find(b"\n\n")
    if head_end < 0:
        m = re.search(rb"ElementDataFile[^\n]*\n", b)
        head_end = m.end() - 1 if m else min(len(b), 2000)
    head, rest = b[:head_end], b[head_end:]
    lines = head.split(b"\n")
    i = rng.randrange(len(lines))
    op = rng.randrange(4)
    if op == 0:
        del lines[i]
    elif op == 1:
        lines.insert(i, lines[i])
    elif op == 2:
        key = lines[i].split(b":")[0].split(b"=")[0]
        sep = b":" if b":" in lines[i] else b"="
        lines[i] = key + sep + b" " + rng.choice([b"", b"x", b"-5", b"1 2", b"\x00\xff", b"a" * 300,
                                                  b"LIST", b"%s%n", b"../../etc/passwd"])
    else:
        lines.insert(i, rng.choice([b"dimension: 4", b"sizes: 3 3 3 3", b"NDims = 7",
                                    b"ElementNumberOfChannels = 3", b"kinds: RGB-color domain domain domain",
                                    b"encoding: gzip", b"endian: big", b"type: double",
                                    b"CompressedData = True", b"HeaderSize = -1",
                                    b"byte skip: -1", b"line skip: 99999999"]))
    return b"\n".join(lines) + rest


def nifti_field(rng, b):
    """Sets a NIfTI-1 header field (dims, datatype, vox_offset, slope, pixdim) to an edge value."""
    b = bytearray(b)
    if len(b) < 348:
        return bytes(b)
    field = rng.choice(["dim", "dim0", "datatype", "bitpix", "vox_offset", "slope", "pixdim", "sizeof"])
    if field == "dim":
        struct.pack_into("<h", b, 40 + 2 * rng.randint(1, 3), rng.choice([0, -1, 1, 32767, 30000, -32768]))
    elif field == "dim0":
        struct.pack_into("<h", b, 40, rng.choice([0, 1, 2, 4, 5, 8, -3, 32767]))
    elif field == "datatype":
        struct.pack_into("<h", b, 70, rng.choice([0, 1, 3, 32, 128, 1536, 2304, 4096, -1]))
    elif field == "bitpix":
        struct.pack_into("<h", b, 72, rng.choice([0, 1, 7, 64, -8]))
    elif field == "vox_offset":
        struct.pack_into("<f", b, 108, rng.choice([0.0, 100.0, 351.0, 353.5, 1e12, 1e20, -352.0,
                                                   float("nan"), float("inf")]))
    elif field == "slope":
        struct.pack_into("<f", b, 112, rng.choice([1e-40, 1e38, -1e38, float("nan"), float("inf"), 1e-30]))
    elif field == "pixdim":
        struct.pack_into("<f", b, 76 + 4 * rng.randint(1, 3), rng.choice([0.0, -1.0, 1e-38, 1e38,
                                                                          float("nan")]))
    else:
        struct.pack_into("<i", b, 0, rng.choice([0, 347, 349, 540, 0x5c010000, -1]))
    return bytes(b)


def huge_claim(rng, b, fmt):
    """A small file whose header claims a huge grid (no data for it)."""
    dims = rng.choice([(30000, 30000, 3), (32768, 32768, 32768), (30000, 30000, 30000), (2, 2, 2**31)])
    if fmt in ("nii", "niigz"):
        h = bytearray(b[:352]) if len(b) >= 352 else bytearray(352)
        for a, d in enumerate(dims):
            struct.pack_into("<h", h, 42 + 2 * a, min(d, 32767))
        out = bytes(h) + b"\x00" * rng.choice([0, 16])
        return out
    text = b.split(b"\n\n")[0].decode("latin-1") if fmt.startswith("nrrd") else b.decode("latin-1")
    s = " ".join(str(d) for d in dims)
    if fmt.startswith("nrrd") or fmt == "nhdr":
        text = re.sub(r"sizes:[^\n]*", "sizes: " + s, text)
        return text.encode("latin-1") + b"\n\n" + b"\x00" * 64
    text = re.sub(r"DimSize = [^\n]*", "DimSize = " + s, text.split("ElementDataFile")[0])
    return (text + "ElementDataFile = LOCAL\n").encode("latin-1") + b"\x00" * 64


def dicom_length(rng, b):
    """Damages one explicit-VR element length in a DICOM slice (the 0.8 GB class)."""
    b = bytearray(b)
    spots = [m.start() for m in re.finditer(rb"(?<=[\x00-\xff]{4})(OB|OW|UN|SQ|UT|US|UL|CS|DS|IS|UI|LO|SH|PN|DA|TM)", bytes(b[132:]))]
    if not spots:
        return flip_bits(rng, bytes(b))
    at = 132 + rng.choice(spots)
    vr = bytes(b[at:at + 2])
    if vr in (b"OB", b"OW", b"UN", b"SQ", b"UT"):
        struct.pack_into("<I", b, at + 4, rng.choice([0xFFFFFFFE, 0x30000000, 0x7FFFFFFF, 1, 3]))
    else:
        struct.pack_into("<H", b, at + 2, rng.choice([0xFFFF, 0xFFFE, 1, 0x8000]))
    return bytes(b)


def gz_recompress(rng, b):
    """For .nii.gz: inflate, damage the NIfTI header, recompress (reaches the header)."""
    try:
        raw = gzip.decompress(b)
    except Exception:
        return flip_bits(rng, b)
    return gzip.compress(nifti_field(rng, raw) if rng.random() < 0.6 else flip_bits(rng, raw))


# ---------------------------------------------------------------------------------------------
# Cases

def write_case(rng, base_dir, base, case_dir):
    """Builds one malformed input under case_dir; returns (input path, mutator name)."""
    name, _kind, _type, out = base
    fmt = name.split("_")[0]
    src = os.path.join(base_dir, name)
    if fmt == "dicom":
        series = os.path.join(case_dir, "series")
        shutil.copytree(os.path.join(src, "series"), series)
        slices = sorted(os.listdir(series))
        victim = os.path.join(series, rng.choice(slices))
        op = rng.choice(["flip", "stomp", "truncate", "length", "length", "device", "fifo",
                         "duplicate", "remove", "junk", "foreign"])
        if op == "device":
            os.remove(victim)
            os.symlink(rng.choice(["/dev/zero", "/dev/urandom", "/dev/null"]), victim)
        elif op == "fifo":
            os.mkfifo(os.path.join(series, "pipe.dcm"))
        elif op == "duplicate":
            shutil.copy(victim, os.path.join(series, "copy.dcm"))
        elif op == "remove":
            os.remove(os.path.join(series, slices[len(slices) // 2]))
        elif op == "foreign":
            with open(os.path.join(series, "notes.txt"), "wb") as f:
                f.write(b"not a slice\n" * rng.randint(1, 100))
        else:
            with open(victim, "rb") as f:
                b = f.read()
            b = {"flip": flip_bits, "stomp": stomp_bytes, "truncate": truncate,
                 "length": dicom_length, "junk": append_junk}[op](rng, b)
            with open(victim, "wb") as f:
                f.write(b)
        return series, "dicom-" + op

    path = os.path.join(case_dir, out)
    shutil.copy(os.path.join(src, out), path)
    companion = None
    if fmt in ("nhdr", "mhd"):
        companion = os.path.join(case_dir, "v.raw")
        shutil.copy(os.path.join(src, "v.raw"), companion)
    with open(path, "rb") as f:
        b = f.read()
    ops = ["flip", "stomp", "truncate", "junk", "huge"]
    if fmt in ("nii", "niigz"):
        ops += ["nifti", "nifti", "nifti"]
    if fmt == "niigz":
        ops += ["regz", "regz"]
    if fmt in ("nrrd", "nhdr", "mha", "mhd"):
        ops += ["numbers", "numbers", "lines", "lines"]
    if fmt in ("nhdr", "mhd"):
        ops += ["data-device", "data-outside", "data-truncate"]
    if fmt == "raw":
        ops += ["rename"]
    op = rng.choice(ops)
    if op == "data-device":
        os.remove(companion)
        os.symlink(rng.choice(["/dev/zero", "/dev/urandom"]), companion)
    elif op == "data-outside":
        target = rng.choice(["/etc/passwd", "/etc/hostname", "../outside.raw", "/dev/zero"])
        if target == "../outside.raw":
            shutil.copy(companion, os.path.join(os.path.dirname(case_dir), "outside.raw"))
        key = b"data file: " if fmt == "nhdr" else b"ElementDataFile = "
        b = re.sub(re.escape(key) + rb"[^\n]*", key + target.encode(), b)
    elif op == "data-truncate":
        with open(companion, "rb") as f:
            d = f.read()
        with open(companion, "wb") as f:
            f.write(truncate(rng, d))
    elif op == "rename":
        new = rng.choice(["v_12x10x80_int16.raw", "v_99999x10x8_int16.raw", "v_12x10x8_float32.raw",
                          "v_0x10x8_int16.raw", "v_12x10x8_int16_be.raw", "v.raw",
                          "v_4294967297x1x1_uint8.raw"])
        newpath = os.path.join(case_dir, new)
        os.rename(path, newpath)
        return newpath, "raw-rename"
    else:
        fn = {"flip": flip_bits, "stomp": stomp_bytes, "truncate": truncate, "junk": append_junk,
              "nifti": nifti_field, "regz": gz_recompress, "numbers": edit_text_numbers,
              "lines": edit_text_lines}.get(op)
        if op == "huge":
            b = huge_claim(rng, b if fmt != "niigz" else gzip.decompress(b), fmt)
            if fmt == "niigz":
                b = gzip.compress(b)
        elif fmt == "niigz" and op == "nifti":
            b = gz_recompress(rng, b)
        else:
            b = fn(rng, b)
    with open(path, "wb") as f:
        f.write(b)
    return path, fmt + "-" + op


def run_one(lacuna, args, cwd, timeout):
    t0 = time.monotonic()
    try:
        p = subprocess.run([lacuna] + args, cwd=cwd, stdin=subprocess.DEVNULL,
                           capture_output=True, timeout=timeout)
        return p.returncode, p.stderr.decode("utf-8", "replace"), time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return "timeout", "", time.monotonic() - t0


def check_case(lacuna, case_dir, inp, timeout):
    """Runs info and render on one input; returns a list of (command, code, problem, stderr)."""
    before = sha(inp)
    companions = {p: sha(os.path.join(case_dir, p)) for p in os.listdir(case_dir)}
    results = []
    out_png = os.path.join(case_dir, "out.png")
    for cmd in (["info", inp], ["render", inp, "--tf", "mr-default", "--size", "24", "--out", out_png]):
        code, err, secs = run_one(lacuna, cmd, case_dir, timeout)
        problem = None
        if code == "timeout":
            problem = "hang"
        elif code < 0:
            problem = "signal %d" % -code
        elif code == 0:
            if cmd[0] == "render" and not os.path.exists(out_png):
                problem = "exit 0 without output"
        elif code == 2:
            if not err.endswith("\n") or err.count("\n") != 1:
                problem = "error is not one line"
            elif cmd[0] == "render" and os.path.exists(out_png):
                problem = "output written on failure"
        else:
            problem = "exit %d" % code
        leftovers = [f for f in os.listdir(case_dir) if f.startswith(".tmp-")]
        if leftovers:
            problem = problem or "temporary left: " + leftovers[0]
        if sha(inp) != before:
            problem = problem or "input modified"
        for p, h in companions.items():
            if os.path.exists(os.path.join(case_dir, p)) and sha(os.path.join(case_dir, p)) != h:
                problem = problem or "companion modified: " + p
        if os.path.exists(out_png):
            os.remove(out_png)
        results.append((cmd[0], code, problem, err.strip()[:300], secs))
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lacuna", required=True)
    ap.add_argument("--count", type=int, default=5000, help="malformed inputs (2 runs each)")
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per run before it is a hang")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--keep", default="", help="folder for violating cases (default: none kept)")
    ap.add_argument("--json", default="", help="write the summary here")
    ap.add_argument("--smoke", action="store_true", help="quiet: print only the summary line")
    a = ap.parse_args()
    lacuna = os.path.abspath(a.lacuna)
    work = tempfile.mkdtemp(prefix="lacuna-mutate-")
    t_start = time.monotonic()
    try:
        base_dir = os.path.join(work, "base")
        for base in BASES:
            name, kind, vtype, out = base
            d = os.path.join(base_dir, name)
            os.makedirs(d)
            target = os.path.join(d, out)
            subprocess.run([lacuna, "generate", kind, "--dims", DIMS, "--type", vtype, "--out", target],
                           check=True, capture_output=True)
            if out.endswith((".nhdr", ".mhd")):
                # The data file is v.raw beside the header.
                assert os.path.exists(os.path.join(d, "v.raw")), "expected v.raw beside " + out
        rng = random.Random(a.seed)
        cases = []
        for i in range(a.count):
            base = BASES[i % len(BASES)]
            holder = os.path.join(work, "cases", "%05d" % i)
            case_dir = os.path.join(holder, "c")
            os.makedirs(case_dir)
            inp, mutator = write_case(random.Random(rng.random()), base_dir, base, case_dir)
            cases.append((i, case_dir, inp, mutator))

        def work_on(c):
            i, case_dir, inp, mutator = c
            return c, check_case(lacuna, case_dir, inp, a.timeout)

        stats = {"inputs": 0, "runs": 0, "exit0": 0, "exit2": 0, "violations": 0, "max_run_s": 0.0,
                 "slowest": ""}
        by_mutator = {}
        violations = []
        with ThreadPoolExecutor(max_workers=a.jobs) as pool:
            for (i, case_dir, inp, mutator), results in pool.map(work_on, cases):
                stats["inputs"] += 1
                m = by_mutator.setdefault(mutator, {"runs": 0, "exit0": 0, "exit2": 0, "violations": 0})
                for cmd, code, problem, err, secs in results:
                    stats["runs"] += 1
                    m["runs"] += 1
                    if secs > stats["max_run_s"]:
                        stats["max_run_s"] = round(secs, 2)
                        stats["slowest"] = "case %d %s %s" % (i, mutator, cmd)
                    if code == 0:
                        stats["exit0"] += 1
                        m["exit0"] += 1
                    elif code == 2:
                        stats["exit2"] += 1
                        m["exit2"] += 1
                    if problem:
                        stats["violations"] += 1
                        m["violations"] += 1
                        violations.append({"case": i, "mutator": mutator, "command": cmd,
                                           "code": code if code != "timeout" else None,
                                           "problem": problem, "stderr": err})
                        if a.keep:
                            dst = os.path.join(a.keep, "%05d-%s" % (i, mutator))
                            if not os.path.exists(dst):
                                shutil.copytree(os.path.dirname(case_dir), dst, symlinks=True)
                        if not a.smoke:
                            print("VIOLATION case %d %s %s: %s: %s" % (i, mutator, cmd, problem, err),
                                  flush=True)
                if not a.smoke and stats["inputs"] % 500 == 0:
                    print("%d inputs, %d runs, %d violations, %.0f s" % (
                        stats["inputs"], stats["runs"], stats["violations"],
                        time.monotonic() - t_start), flush=True)
        stats["seconds"] = round(time.monotonic() - t_start, 1)
        summary = {"stats": stats, "by_mutator": by_mutator, "violations": violations[:200],
                   "seed": a.seed, "count": a.count}
        if a.json:
            with open(a.json, "w") as f:
                json.dump(summary, f, indent=1, sort_keys=True)
        if not a.smoke:
            for k in sorted(by_mutator):
                v = by_mutator[k]
                print("  %-22s runs %5d  exit0 %5d  exit2 %5d  violations %d" % (
                    k, v["runs"], v["exit0"], v["exit2"], v["violations"]))
        print("mutation campaign: %(inputs)d inputs, %(runs)d runs, %(exit0)d exit 0, %(exit2)d exit 2, "
              "%(violations)d violations, slowest run %(max_run_s)s s (%(slowest)s), %(seconds)s s" % stats)
        for v in violations[:20]:
            print("  case %(case)d %(mutator)s %(command)s: %(problem)s: %(stderr)s" % v)
        return 1 if stats["violations"] else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
