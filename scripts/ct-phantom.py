#!/usr/bin/python3
"""A CT-like torso in Hounsfield units, for pictures of the CT presets (docs/transfer-functions.md).

No CT scan is packaged on Debian, and `lacuna generate` has no anatomy (docs/synthetic.md), so
this writes one with numpy and nibabel: an elliptic torso 2.5 mm per voxel, int16, RAS affine
(axis 0 right->left, 1 anterior->posterior as rows of the image, 2 inferior->superior).

  air -1000 outside; skin and fat -100 (15 mm); muscle and organs 40
  two lungs -850 with a few dozen vessels (40 HU, 2-4 mm radius) inside them
  a heart 40 with a contrast-filled chamber 300; an aorta 300 (ascending, arch, descending)
  a spine: vertebral bodies 250 (trabecular) in a 1200 shell, discs 80, spinous processes
  ribs 1000 on elliptic arcs; a sternum 700
  gaussian noise sigma 12 HU (seeded: the file is the same on every run)

Usage: ct-phantom.py OUT.nii.gz
"""
import sys

import nibabel as nib
import numpy as np

SP = 2.5  # mm per voxel
NX, NY, NZ = 144, 112, 100


def main(out):
    rng = np.random.default_rng(18)
    x = (np.arange(NX) - (NX - 1) / 2) * SP  # mm, + to the patient's left
    y = (np.arange(NY) - (NY - 1) / 2) * SP  # mm, + posterior
    z = (np.arange(NZ) - (NZ - 1) / 2) * SP  # mm, + superior
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    v = np.full((NX, NY, NZ), -1000.0, np.float32)

    def ellipse(cx, cy, a, b):
        return ((X - cx) / a) ** 2 + ((Y - cy) / b) ** 2

    body = ellipse(0, 0, 165, 115) <= 1
    v[body] = -100.0
    v[ellipse(0, 0, 150, 100) <= 1] = 40.0
    # Lungs: ellipsoids either side, above the diaphragm (z > -70 mm).
    lungs = np.zeros_like(body)
    for side in (-1, 1):
        e = ((X - side * 72) / 55) ** 2 + ((Y + 5) / 70) ** 2 + ((Z - 20) / 105) ** 2
        lungs |= (e <= 1) & (Z > -75)
    v[lungs] = -850.0
    # Vessels in the lungs: random segments from the hila outwards.
    for _ in range(40):
        side = rng.choice((-1, 1))
        p0 = np.array([side * 35.0, 0.0, rng.uniform(-20, 40)])
        d = rng.normal(size=3)
        d[0] = side * abs(d[0]) + side * 0.8
        d /= np.linalg.norm(d)
        length, r = rng.uniform(40, 110), rng.uniform(2.0, 4.0)
        t = np.clip(((X - p0[0]) * d[0] + (Y - p0[1]) * d[1] + (Z - p0[2]) * d[2]) / length, 0, 1)
        dist2 = (X - p0[0] - t * length * d[0]) ** 2 + (Y - p0[1] - t * length * d[1]) ** 2 + (
            Z - p0[2] - t * length * d[2]) ** 2
        v[(dist2 <= r * r) & lungs] = 40.0
    # Heart with a contrast chamber, anterior and a little to the left.
    heart = ((X - 15) / 55) ** 2 + ((Y + 35) / 45) ** 2 + ((Z + 5) / 50) ** 2 <= 1
    v[heart] = 40.0
    v[((X - 20) / 25) ** 2 + ((Y + 35) / 20) ** 2 + ((Z + 5) / 28) ** 2 <= 1] = 300.0
    # Aorta: ascending in front, an arch over the heart, descending left of the spine.
    r_ao = 13.0
    asc = ((X - 5) ** 2 + (Y + 25) ** 2 <= r_ao ** 2) & (Z > 0) & (Z < 75)
    desc = ((X - 25) ** 2 + (Y - 45) ** 2 <= r_ao ** 2) & (Z < 75)
    # The arch: a half circle in the vertical plane through the two, over z = 75.
    u = np.array([25.0 - 5.0, 45.0 + 25.0])
    R = np.linalg.norm(u) / 2
    u /= np.linalg.norm(u)
    cx, cy = 15.0, 10.0
    w = (X - cx) * u[0] + (Y - cy) * u[1]   # along the plane
    n = -(X - cx) * u[1] + (Y - cy) * u[0]  # across it
    h = Z - 75.0
    arch = ((np.sqrt(w ** 2 + h ** 2) - R) ** 2 + n ** 2 <= r_ao ** 2) & (h >= 0)
    v[asc | desc | arch] = 300.0
    # Spine: vertebral bodies (cortical shell, trabecular core), discs, spinous processes.
    for k, zc in enumerate(np.arange(-110, 125, 27.5)):
        body_v = ((X ** 2 + (Y - 62) ** 2) <= 22 ** 2) & (np.abs(Z - zc) <= 11)
        core = ((X ** 2 + (Y - 62) ** 2) <= 18 ** 2) & (np.abs(Z - zc) <= 8)
        disc = ((X ** 2 + (Y - 62) ** 2) <= 20 ** 2) & (np.abs(Z - zc - 13.75) <= 2.5)
        spin = (np.abs(X) <= 5) & (Y > 84) & (Y < 108) & (np.abs(Z - zc) <= 8)
        v[body_v | spin] = 1200.0
        v[core] = 250.0
        v[disc] = 80.0
    # Ribs: tubes on elliptic arcs around the chest, every 25 mm.
    th = np.arctan2(Y / 100, X / 150)
    re = np.sqrt((X / 150) ** 2 + (Y / 100) ** 2)
    for zc in np.arange(-60, 110, 25):
        zr = zc + 12 * np.sin(th)  # tilted: lower at the front
        ring = ((re - 0.93) * 120) ** 2 + (Z - zr) ** 2 <= 6.5 ** 2
        v[ring & (np.abs(X) > 25)] = 1000.0
    # Sternum.
    v[(np.abs(X) <= 14) & (Y > -108) & (Y < -92) & (Z > -40) & (Z < 90)] = 700.0
    v[body] += rng.normal(0, 12, size=int(body.sum())).astype(np.float32)
    v = np.clip(np.round(v), -1024, 3071).astype(np.int16)
    # RAS: x to the patient's left is -R; rows run anterior to posterior, so y flips too.
    aff = np.diag([-SP, -SP, SP, 1.0])
    aff[:3, 3] = [(NX - 1) / 2 * SP, (NY - 1) / 2 * SP, -(NZ - 1) / 2 * SP]
    img = nib.Nifti1Image(v, aff)
    img.header.set_xyzt_units("mm")
    img.set_qform(aff, code=1)
    img.set_sform(aff, code=1)
    nib.save(img, out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: ct-phantom.py OUT.nii.gz")
    main(sys.argv[1])
