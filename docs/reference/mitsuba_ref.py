#!/usr/bin/env python3
"""Independent reference renderer: renders a scene JSON (format: docs/scene-format.md) with
Mitsuba 3 and writes a linear float32 RGB EXR.

  python3 docs/reference/mitsuba_ref.py docs/scenes/s1_forest_spheres.json --spp 64 --seed 0 --out s1.exr
  options: --variant llvm_ad_rgb|scalar_rgb   --integrator direct|path2   --passes N
           --warmup (render once, untimed, before the timed render: excludes LLVM JIT compile time)
           --stderr-out FILE (with --passes>=2: per-pixel std. error of the mean image)
           --coverage-out FILE (geometry coverage per pixel, 0..1, from a black-shapes/white-env render)
Prints 'render_seconds: X' = wall time of the rendering calls only (scene loading excluded), and
'render_cpu_seconds: Y' = the CPU time of every thread of the process over the same calls.
With --passes N the image is the mean of N renders of spp/N samples each (seeds (seed*65537+k) mod 2^32),
which with the box pixel filter is exactly equivalent to one render with spp samples.
"""
import argparse, json, os, sys, time

def _setup_llvm():
    # drjit 1.5 emits llvm.minimum, which the Debian LLVM 15 cannot select on x86 -> use LLVM 19 if present.
    if 'DRJIT_LIBLLVM_PATH' not in os.environ:
        for p in ['/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1', '/usr/lib/llvm-19/lib/libLLVM.so.1',
                  '/usr/lib/x86_64-linux-gnu/libLLVM-19.so']:
            if os.path.exists(p):
                os.environ['DRJIT_LIBLLVM_PATH'] = p
                break

def rgb(v):
    v = [float(x) for x in (v if isinstance(v, (list, tuple)) else [v, v, v])]
    return {'type': 'rgb', 'value': v}

def material_dict(m):
    t = m['type']
    if t == 'diffuse':
        b = {'type': 'diffuse', 'reflectance': rgb(m.get('albedo', [0.5, 0.5, 0.5]))}
    elif t == 'roughconductor':
        b = {'type': 'roughconductor', 'distribution': m.get('distribution', 'ggx'),
             'alpha': float(m['alpha']), 'material': 'none',            # 'none' => Fresnel F = 1
             'specular_reflectance': rgb(m.get('specular', [1, 1, 1])),
             'sample_visible': bool(m.get('sample_visible', True))}
    elif t == 'roughplastic':
        b = {'type': 'roughplastic', 'distribution': m.get('distribution', 'ggx'),
             'alpha': float(m['alpha']), 'int_ior': float(m.get('int_ior', 1.49)),
             'ext_ior': float(m.get('ext_ior', 1.0)),
             'diffuse_reflectance': rgb(m.get('albedo', [0.5, 0.5, 0.5])),
             'specular_reflectance': rgb(m.get('specular', [1, 1, 1])),
             'nonlinear': bool(m.get('nonlinear', False))}
    else:
        raise ValueError('unknown material ' + t)
    if m.get('twosided', False):
        b = {'type': 'twosided', 'bsdf': b}
    return b

def sampler_type():
    """Mitsuba sampler: PEER_SAMPLER or --sampler (independent, ldsampler, multijitter, stratified, orthogonal)."""
    return os.environ.get('PEER_SAMPLER', 'independent')

def _frame_to_world(center, normal, scale):
    """4x4 (list) mapping local z to `normal`, scaled by `scale` in x, y, z, translated to `center`."""
    import numpy as np
    n = np.array(normal, dtype=float); n /= np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t = np.cross(n, a); t /= np.linalg.norm(t); b = np.cross(n, t)
    M = np.eye(4); M[:3, 0] = t * scale; M[:3, 1] = b * scale; M[:3, 2] = n * scale; M[:3, 3] = center
    return M.tolist()

def light_dict(l, base_dir, override=None):
    """One entry of a scene's `lights` (docs/scene-format.md) as a Mitsuba emitter or emitting shape."""
    import math
    import numpy as np
    import mitsuba as mi
    T = mi.ScalarTransform4f
    t = l['type']
    if 'shaping' in l:
        # Mitsuba has no IES profile and its spot's soft band is linear, not the schema's smoothstep.
        raise SystemExit(f"mitsuba_ref.py: a {t} light with `shaping` has no Mitsuba equivalent")
    black = {'type': 'diffuse', 'reflectance': rgb([0, 0, 0])}
    area = lambda: {'type': 'area', 'radiance': rgb([0, 0, 0] if override == 'coverage' else l['radiance'])}
    zero = override == 'coverage'
    if t == 'point':
        return {'type': 'point', 'position': [float(x) for x in l['position']],
                'intensity': rgb([0, 0, 0] if zero else l['intensity'])}
    if t == 'sphere':
        return {'type': 'sphere', 'center': [float(x) for x in l['center']], 'radius': float(l['radius']),
                'bsdf': black, 'emitter': area()}
    if t == 'rectangle':
        p0, e1, e2 = (np.array(l[k], dtype=float) for k in ('p0', 'e1', 'e2'))
        n = np.cross(e1, e2); n /= np.linalg.norm(n)
        c = p0 + 0.5 * e1 + 0.5 * e2
        M = np.eye(4); M[:3, 0] = 0.5 * e1; M[:3, 1] = 0.5 * e2; M[:3, 2] = n; M[:3, 3] = c
        return {'type': 'rectangle', 'to_world': T(M.tolist()), 'bsdf': black, 'emitter': area()}
    if t == 'disk':
        return {'type': 'disk', 'to_world': T(_frame_to_world(l['center'], l['normal'], float(l['radius']))),
                'bsdf': black, 'emitter': area()}
    if t == 'mesh':
        fn = l['file'] if os.path.isabs(l['file']) else os.path.normpath(os.path.join(base_dir, l['file']))
        sd = {'type': 'obj' if fn.lower().endswith('.obj') else 'ply', 'filename': fn, 'face_normals': True,
              'bsdf': black, 'emitter': area()}
        if 'to_world' in l:
            sd['to_world'] = T(l['to_world'])
        return sd
    if t == 'distant':
        if zero:
            return None          # not a surface: its twin sphere must not count as covered pixels
        dvec = np.array(l['direction'], dtype=float); dvec /= np.linalg.norm(dvec)
        E = [0.0, 0.0, 0.0] if zero else [float(x) for x in (l['irradiance'] if isinstance(l['irradiance'], (list, tuple)) else [l['irradiance']] * 3)]
        theta = math.radians(float(l.get('angle_deg', 0.0)))
        if theta <= 0:
            return {'type': 'directional', 'direction': [float(-x) for x in dvec], 'irradiance': rgb(E)}
        h = 0.5 * theta; R = 1e5
        L = [e / (math.pi * math.sin(h) ** 2) for e in E]
        return {'type': 'sphere', 'center': [float(x) for x in dvec * R], 'radius': R * math.sin(h),
                'bsdf': black, 'emitter': {'type': 'area', 'radiance': rgb(L)}}
    raise ValueError('unknown light ' + t)

def build_scene(sc, base_dir, spp, seed, integrator='direct', override=None):
    import mitsuba as mi
    T = mi.ScalarTransform4f
    cam = sc['camera']
    d = {'type': 'scene'}
    d['sensor'] = {
        'type': 'perspective', 'fov': float(cam['fov_y_deg']), 'fov_axis': 'y',
        'near_clip': float(cam.get('near_clip', 1e-3)), 'far_clip': float(cam.get('far_clip', 1e5)),
        'to_world': T().look_at(origin=cam['origin'], target=cam['target'], up=cam['up']),
        'sampler': {'type': sampler_type(), 'sample_count': int(spp), 'seed': int(seed)},
        'film': {'type': 'hdrfilm', 'width': int(cam['width']), 'height': int(cam['height']),
                 'rfilter': {'type': 'box'}, 'pixel_format': 'rgb', 'component_format': 'float32'}}
    hide = bool(sc.get('hide_emitters', False))
    if integrator == 'direct':
        d['integrator'] = {'type': 'direct', 'emitter_samples': 1, 'bsdf_samples': 1, 'hide_emitters': hide}
    elif integrator == 'path2':
        d['integrator'] = {'type': 'path', 'max_depth': 2, 'hide_emitters': hide}
    else:
        raise ValueError(integrator)
    env = sc.get('envmap')
    if override == 'coverage':
        d['env'] = {'type': 'constant', 'radiance': rgb([1, 1, 1])}
    elif env is not None:
        fn = env['file'] if os.path.isabs(env['file']) else os.path.normpath(os.path.join(base_dir, env['file']))
        d['env'] = {'type': 'envmap', 'filename': fn, 'scale': float(env.get('scale', 1.0)),
                    'to_world': T().rotate([0, 1, 0], float(env.get('rotate_y_deg', 0.0)))}
    for k, l in enumerate(sc.get('lights', [])):
        e = light_dict(l, base_dir, override)
        if e is not None:
            d[f'light_{k:03d}'] = e
    for k, s in enumerate(sc['shapes']):
        bsdf = material_dict(s['material'])
        if override == 'coverage':
            bsdf = {'type': 'twosided', 'bsdf': {'type': 'diffuse', 'reflectance': rgb([0, 0, 0])}}
        if s['type'] == 'sphere':
            sd = {'type': 'sphere', 'center': [float(x) for x in s['center']], 'radius': float(s['radius'])}
        elif s['type'] == 'rectangle':
            import numpy as np
            p0, e1, e2 = (np.array(s[k_], dtype=float) for k_ in ('p0', 'e1', 'e2'))
            n = np.cross(e1, e2); n /= np.linalg.norm(n)
            c = p0 + 0.5 * e1 + 0.5 * e2
            M = np.eye(4); M[:3, 0] = 0.5 * e1; M[:3, 1] = 0.5 * e2; M[:3, 2] = n; M[:3, 3] = c
            sd = {'type': 'rectangle', 'to_world': T(M.tolist())}
        elif s['type'] == 'mesh':
            fn = s['file'] if os.path.isabs(s['file']) else os.path.normpath(os.path.join(base_dir, s['file']))
            sd = {'type': 'obj' if fn.lower().endswith('.obj') else 'ply', 'filename': fn,
                  'face_normals': bool(s.get('face_normals', True))}
            if 'to_world' in s:
                sd['to_world'] = T(s['to_world'])
        else:
            raise ValueError('unknown shape ' + s['type'])
        sd['bsdf'] = bsdf
        d[f'shape_{k:03d}'] = sd
    return d

def render(scene_json, spp, seed, variant='llvm_ad_rgb', integrator='direct', passes=1, warmup=False,
           override=None, verbose=True):
    """Returns (image HxWx3 float32 numpy, (render_seconds, render_cpu_seconds), per-pixel std error or None)."""
    if variant.startswith('llvm'):
        _setup_llvm()
    import numpy as np, mitsuba as mi, drjit as dr
    mi.set_variant(variant)
    with open(scene_json) as f:
        sc = json.load(f)
    base = os.path.dirname(os.path.abspath(scene_json))
    assert spp % passes == 0, 'spp must be divisible by passes'
    spp_pass = spp // passes
    scene = mi.load_dict(build_scene(sc, base, spp_pass, seed, integrator, override))
    if warmup:
        img = mi.render(scene, spp=spp_pass, seed=seed + 999331)
        dr.eval(img); dr.sync_thread()
    acc = None; acc2 = None
    t0, c0 = time.perf_counter(), time.process_time()
    for k in range(passes):
        s = seed if passes == 1 else (seed * 65537 + k) % 2**32
        img = mi.render(scene, spp=spp_pass, seed=s)
        dr.eval(img); dr.sync_thread()
        a = np.array(img, dtype=np.float64)
        acc = a if acc is None else acc + a
        acc2 = a * a if acc2 is None else acc2 + a * a
    secs = (time.perf_counter() - t0, time.process_time() - c0)
    mean = acc / passes
    se = None
    if passes >= 2:
        var = np.maximum(acc2 / passes - mean * mean, 0) * passes / (passes - 1)
        se = np.sqrt(var / passes).astype(np.float32)
    return mean.astype(np.float32), secs, se

def write_exr(path, a):
    import numpy as np, mitsuba as mi
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    b = mi.Bitmap(np.ascontiguousarray(a, dtype=np.float32), mi.Bitmap.PixelFormat.RGB)
    b.write(path)

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scene'); ap.add_argument('--spp', type=int, default=64)
    ap.add_argument('--seed', type=int, default=0); ap.add_argument('--out', required=True)
    ap.add_argument('--variant', default='llvm_ad_rgb')
    ap.add_argument('--integrator', default='direct', choices=['direct', 'path2'])
    ap.add_argument('--passes', type=int, default=1); ap.add_argument('--warmup', action='store_true')
    ap.add_argument('--stderr-out'); ap.add_argument('--coverage-out')
    ap.add_argument('--sampler', help='Mitsuba sampler (default independent; ldsampler is its best on these scenes)')
    a = ap.parse_args()
    if a.sampler:
        os.environ['PEER_SAMPLER'] = a.sampler
    img, secs, se = render(a.scene, a.spp, a.seed, a.variant, a.integrator, a.passes, a.warmup)
    write_exr(a.out, img)
    print(f'render_seconds: {secs[0]:.4f}  render_cpu_seconds: {secs[1]:.4f}  (variant={a.variant}, integrator={a.integrator}, sampler={sampler_type()}, spp={a.spp}, '
          f'passes={a.passes}, seed={a.seed}, warmup={a.warmup})')
    if a.stderr_out and se is not None:
        write_exr(a.stderr_out, se)
    if a.coverage_out:
        cov, _, _ = render(a.scene, 256, 7, a.variant, 'direct', 1, False, override='coverage')
        write_exr(a.coverage_out, 1.0 - cov)

if __name__ == '__main__':
    main()
