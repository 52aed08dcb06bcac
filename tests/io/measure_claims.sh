#!/usr/bin/env bash
# Issue 15's targets, measured (docs/reliability.md, "Targets checked"): tiny files whose headers
# claim 30000^3 int16 voxels (54 TB) in each format, run through `lacuna info` and `lacuna
# render` under /usr/bin/time -v. Prints per run: wall time, CPU seconds (user + system, what
# the load of a shared machine does not inflate), max RSS, exit code, the number of stderr lines,
# whether anything was written, whether the input is unchanged, and the line.
# The pass/fail part of this (one line, exit 2, nothing written, input untouched) is the ctest
# IoBudget.CliRefusesA30000CubedClaimInOneLineAndWritesNothing; this script only measures.
# Usage: tests/io/measure_claims.sh [path/to/lacuna]        (default build/lacuna)
set -euo pipefail
cli=$(realpath "${1:-build/lacuna}")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/in" "$tmp/out"
/usr/bin/python3 - "$tmp/in" <<'EOF'
import gzip, struct, sys
d = sys.argv[1]
# NIfTI-1: sizeof_hdr 348, dim = [3, 30000, 30000, 30000, 1, 1, 1, 1], int16 (datatype 4,
# bitpix 16), pixdim 1, vox_offset 352, magic "n+1", then 4 extension bytes and 16 voxel bytes.
h = bytearray(348)
struct.pack_into("<i", h, 0, 348)
struct.pack_into("<8h", h, 40, 3, 30000, 30000, 30000, 1, 1, 1, 1)
struct.pack_into("<hh", h, 70, 4, 16)
struct.pack_into("<8f", h, 76, 1, 1, 1, 1, 1, 1, 1, 1)
struct.pack_into("<f", h, 108, 352)
struct.pack_into("<f", h, 112, 1)  # scl_slope
struct.pack_into("<hh", h, 252, 1, 0)  # qform_code 1 (scanner), sform_code 0
struct.pack_into("<f", h, 256, 0)  # quatern_b .. (identity)
h[344:348] = b"n+1\0"
nii = bytes(h) + b"\0" * 4 + b"\0" * 16
open(f"{d}/claim.nii", "wb").write(nii)
open(f"{d}/claim.nii.gz", "wb").write(gzip.compress(nii, 9, mtime=0))
tail = b"\0" * 16
nrrd = (b"NRRD0004\ntype: short\ndimension: 3\nsizes: 30000 30000 30000\n"
        b"endian: little\nencoding: raw\n\n")
mha = (b"ObjectType = Image\nNDims = 3\nDimSize = 30000 30000 30000\n"
       b"ElementType = MET_SHORT\nElementDataFile = LOCAL\n")
open(f"{d}/claim.nrrd", "wb").write(nrrd + tail)
open(f"{d}/claim.mha", "wb").write(mha + tail)
EOF
printf '%-20s %-6s %8s %6s %9s %4s %5s %7s %9s  %s\n' file cmd wall cpu_s maxrss_kB exit lines written unchanged stderr
for f in claim.nii.gz claim.nii claim.nrrd claim.mha; do
  in="$tmp/in/$f"
  sum=$(sha256sum "$in" | cut -d' ' -f1)
  for cmd in info render; do
    args=(info "$in")
    [ "$cmd" = render ] &&
      args=(render "$in" --tf mr-default --size 16 --out "$tmp/out/frame.png")
    set +e
    /usr/bin/time -v -o "$tmp/time.txt" "$cli" "${args[@]}" >/dev/null 2>"$tmp/err.txt"
    code=$?
    set -e
    wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$tmp/time.txt")
    cpu=$(awk -F': ' '/User time|System time/ {t += $2} END {printf "%.2f", t}' "$tmp/time.txt")
    rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$tmp/time.txt")
    lines=$(wc -l <"$tmp/err.txt")
    written=$(ls -A "$tmp/out" | wc -l)
    [ "$(sha256sum "$in" | cut -d' ' -f1)" = "$sum" ] && same=yes || same=NO
    printf '%-20s %-6s %8s %6s %9s %4s %5s %7s %9s  %s\n' "$f ($(stat -c %s "$in") B)" "$cmd" \
      "$wall" "$cpu" "$rss" "$code" "$lines" "$written" "$same" "$(head -1 "$tmp/err.txt")"
  done
done
