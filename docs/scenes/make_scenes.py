#!/usr/bin/env python3
"""Writes the environment maps of our two comparison scenes (docs/stability.md):

  furnace.json     — a Lambert sphere (albedo 0.5) alone under a constant map of radiance 1:
                     every pixel on it converges to 0.5 exactly (a convex object does not
                     shadow itself).
  sharp_sun.json   — a GGX conductor sphere with α = 0.01 and a grey ground under a dim sky
                     (0.05) with a sun of radius 0.5° and radiance 2e4 (4e5× the sky, in a
                     1024×512 map): the sharp highlight of a small sun.
  studio.json      — glossy GGX spheres (α = 0.05, 0.15, 0.3) on a grey floor under a dark
                     studio (0.02) lit by 24 soft boxes (discs of 3–6°, radiance 20–200): the
                     structured lighting under a glossy lobe where the paper's product pays —
                     neither factor is a near-delta, so neither env nor BRDF sampling alone
                     finds where their product is large.
  default_twin.json — the embedded default scene in the scene format, for renderers that read
                     only files (Mitsuba): its sky with the sun written as a 4096×2048 lat-long
                     map (default_sky.exr, the sun's edge by 8×8 coverage samples per pixel),
                     its car-paint sphere a GGX conductor of α = 0.05 (the format has no car
                     paint), at 384×216.
  knot.json        — a 100 000-triangle torus knot (GGX α = 0.1, face normals) on a grey floor
                     under the courtyard map: a scene whose cost is in its geometry
                     (knot.ply, binary PLY).
  alphas_{default,s3,sharp}.json — default_twin.json's view with GGX conductor spheres of
                     α = 0.1, 0.2, 0.3 and 0.5 under three suns: the default sky's, s3's sunset
                     and sharp_sun's map (committed; the maps as above).

  pip install numpy; python3 docs/scenes/make_scenes.py
The maps and the knot are generated (not committed). The maps are float32 RGB OpenEXR, written
here (ZIP-compressed scanlines): numpy is all the script needs. Orientation: the project's
lat-long convention, u = atan2(x, −z)/2π, v = acos(y)/π (docs/conventions.md)."""
import os
import struct
import zlib
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def write_exr(path, img):
    """img (h, w, 3) as a float32 RGB OpenEXR: scanlines, ZIP compression (16 lines per
    chunk), the attributes OpenEXR requires and no others."""
    img = np.ascontiguousarray(img, dtype="<f4")
    h, w, _ = img.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    window = struct.pack("<4i", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2)
              + attr("channels", "chlist", chlist) + attr("compression", "compression", b"\x03")
              + attr("dataWindow", "box2i", window) + attr("displayWindow", "box2i", window)
              + attr("lineOrder", "lineOrder", b"\x00") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    chunks = []
    for y0 in range(0, h, 16):
        # Per scanline the channels in the header's order (B, G, R), each a row of w floats.
        raw = np.ascontiguousarray(img[y0:y0 + 16, :, ::-1].transpose(0, 2, 1)).tobytes()
        b = np.frombuffer(raw, dtype=np.uint8)
        # OpenEXR's ZIP: even bytes then odd bytes, then each byte as the difference from the last.
        t = np.concatenate([b[0::2], b[1::2]])
        d = t.copy()
        d[1:] = (t[1:].astype(np.int16) - t[:-1] + 128) & 0xFF
        z = zlib.compress(d.tobytes(), 6)
        data = z if len(z) < len(raw) else raw
        chunks.append(struct.pack("<ii", y0, len(data)) + data)
    offset = len(header) + 8 * len(chunks)
    table = b""
    for c in chunks:
        table += struct.pack("<Q", offset)
        offset += len(c)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(chunks))


def write(name, img):
    write_exr(os.path.join(HERE, name), img.astype(np.float32))


def latlong_directions(w, h):
    """The unit direction of each pixel centre of a w × h lat-long map (the project's
    convention), shape (h, w, 3)."""
    v, u = np.meshgrid((np.arange(h) + 0.5) / h, (np.arange(w) + 0.5) / w, indexing="ij")
    theta, phi = v * np.pi, u * 2 * np.pi
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)


def sharp_sun_map(w=1024, h=512):
    """A sun of 0.5° radius, 4e5× a constant sky."""
    d = latlong_directions(w, h)
    sun = np.array([0.35, 0.55, 0.76])
    sun /= np.linalg.norm(sun)
    inside = d @ sun > np.cos(np.radians(0.5))
    img = np.full((h, w, 3), 0.05)
    img[inside] = 2.0e4
    return img, int(inside.sum())


def studio_map(seed=7, w=1024, h=512):
    """studio.json's map: 24 discs of 3–6° radius and radiance 20–200 above the horizon over a
    dark studio (0.02); other seeds place other discs the same way."""
    d = latlong_directions(w, h)
    rng = np.random.default_rng(seed)
    img = np.full((h, w, 3), 0.02)
    for _ in range(24):
        # Above the horizon: y = cos θ uniform in [0, 0.95].
        y = rng.uniform(0.0, 0.95)
        a = rng.uniform(0, 2 * np.pi)
        c = np.array([np.sqrt(1 - y * y) * np.sin(a), y, -np.sqrt(1 - y * y) * np.cos(a)])
        radius = np.radians(rng.uniform(3.0, 6.0))
        colour = rng.uniform(20.0, 200.0) * rng.uniform(0.8, 1.0, 3)
        img[d @ c > np.cos(radius)] = colour
    return img


def default_sky(w=4096, h=2048, ss=8):
    """host-std/src/light/sky.rs's default sky: a blue gradient above the horizon, a dim ground
    below, a sun of 0.265° radius at 35° elevation and 40° azimuth, 1e5 × (1, 0.92, 0.82)."""
    el, az = np.radians(35.0), np.radians(40.0)
    sun = np.array([np.cos(el) * np.sin(az), np.sin(el), -np.cos(el) * np.cos(az)])
    zenith, horizon, ground = np.array([0.12, 0.24, 0.5]), np.array([0.55, 0.62, 0.72]), np.array([0.09, 0.085, 0.08])
    v, u = np.meshgrid((np.arange(h) + 0.5) / h, (np.arange(w) + 0.5) / w, indexing="ij")
    y = np.cos(v * np.pi)
    t = np.clip(y, 0.0, 1.0) ** 0.4
    img = np.where((y >= 0.0)[..., None], horizon + (zenith - horizon) * t[..., None], ground)
    # The sun's pixels: coverage by ss × ss samples in a window around it.
    cos_r = np.cos(np.radians(0.265))
    theta_s, phi_s = np.arccos(sun[1]), np.arctan2(sun[0], -sun[2]) % (2 * np.pi)
    r0, c0 = int(theta_s / np.pi * h), int(phi_s / (2 * np.pi) * w)
    win = 16
    for r in range(r0 - win, r0 + win):
        for c in range(c0 - win, c0 + win):
            sv = (r + (np.arange(ss) + 0.5) / ss) / h * np.pi
            su = (c + (np.arange(ss) + 0.5) / ss) / w * 2 * np.pi
            th, ph = np.meshgrid(sv, su, indexing="ij")
            dd = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], axis=-1)
            cover = np.mean(dd @ sun >= cos_r)
            img[r, c] += 1.0e5 * np.array([1.0, 0.92, 0.82]) * cover
    return img



def torus_knot(p=2, q=3, segments=1250, sides=40, tube=0.16):
    """A (p, q) torus knot tube: segments × sides quads, 2 triangles each (100 000 for the
    defaults), centred on the origin, about 2.4 wide."""
    t = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    def curve(t):
        r = 0.8 + 0.35 * np.cos(q * t)
        return np.stack([r * np.cos(p * t), 0.35 * np.sin(q * t), r * np.sin(p * t)], axis=-1)
    c, cn = curve(t), curve(t + 1e-4)
    tangent = (cn - c) / np.linalg.norm(cn - c, axis=-1, keepdims=True)
    normal = np.cross(tangent, np.array([0.0, 1.0, 0.0]))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    binormal = np.cross(tangent, normal)
    a = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    ring = np.cos(a)[None, :, None] * normal[:, None, :] + np.sin(a)[None, :, None] * binormal[:, None, :]
    verts = (c[:, None, :] + tube * ring).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    v00 = i * sides + j
    v10 = ((i + 1) % segments) * sides + j
    v01 = i * sides + (j + 1) % sides
    v11 = ((i + 1) % segments) * sides + (j + 1) % sides
    # Wound so that e1 × e2 points out of the tube (the front face).
    faces = np.concatenate([np.stack([v00, v11, v10], -1).reshape(-1, 3), np.stack([v00, v01, v11], -1).reshape(-1, 3)])
    return verts.astype(np.float32), faces.astype(np.int32)


def write_ply(name, verts, faces):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rows["n"], rows["i"] = 3, faces
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(header.encode())
        f.write(verts.astype("<f4").tobytes())
        f.write(rows.tobytes())


def main():
    write("furnace_env.exr", np.ones((32, 64, 3)))
    img, texels = sharp_sun_map()
    write("sharp_sun_env.exr", img)
    print(f"sun texels: {texels}")
    write("studio_env.exr", studio_map())
    write("default_sky.exr", default_sky())
    verts, faces = torus_knot()
    # Lift it so that it rests above the floor at y = 0.
    verts[:, 1] += 0.6
    write_ply("knot.ply", verts, faces)
    print(f"knot: {len(faces)} triangles")


if __name__ == "__main__":
    main()
