//! What a host asks of a BRDF instead of matching on its type: whether it is diffuse, how wide
//! its sharpest lobe is, and whether it bounds itself over cones.

use sampler_core::brdf::{Brdf, BrdfSample, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::cone::Cone;
use sampler_core::glam::{Vec2, Vec3};
use std::f32::consts::FRAC_PI_2;

/// An engine's material that says nothing beyond the three required methods.
struct Opaque;

impl Brdf for Opaque {
    fn eval(&self, _: Vec3, wi: Vec3) -> Vec3 {
        Vec3::splat(wi.z.max(0.0))
    }
    fn sample(&self, _: Vec3, _: Vec2) -> Option<BrdfSample> {
        None
    }
    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }
}

/// The same material, diffuse by its own word.
struct OpaqueDiffuse;

impl Brdf for OpaqueDiffuse {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        Opaque.eval(wo, wi)
    }
    fn sample(&self, _: Vec3, _: Vec2) -> Option<BrdfSample> {
        None
    }
    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }
    fn is_diffuse(&self) -> bool {
        true
    }
}

#[test]
fn the_built_in_brdfs_say_how_wide_their_sharpest_lobe_is() {
    let phong = Phong::new(Vec3::splat(0.2), Vec3::splat(0.5), 198.0);
    let paint = CarPaint::default();
    let no_coat = CarPaint { coat: 0.0, ..paint };
    let bare = CarPaint { coat: 0.0, flake: Vec3::ZERO, ..paint };
    let cases: [(&str, &dyn Brdf, f32, bool); 7] = [
        ("lambert", &Lambert::new(Vec3::ONE), FRAC_PI_2, true),
        ("ggx α=0.05", &RoughConductor::new(0.05, Vec3::ONE), 0.05, false),
        ("phong n=198", &phong, 0.1, false),
        ("phong without ks", &Phong::new(Vec3::splat(0.5), Vec3::ZERO, 198.0), FRAC_PI_2, true),
        ("car paint", &paint, paint.coat_ggx.alpha(), false),
        ("car paint without coat", &no_coat, paint.flake_ggx.alpha(), false),
        ("car paint base only", &bare, FRAC_PI_2, true),
    ];
    for (name, brdf, width, diffuse) in cases {
        assert!((brdf.lobe_width() - width).abs() < 1e-6, "{name}: {} ≠ {width}", brdf.lobe_width());
        assert_eq!(brdf.is_diffuse(), diffuse, "{name}");
        assert!(brdf.has_cone_bounds(), "{name} bounds itself over cones");
    }
}

#[test]
fn a_brdf_that_says_nothing_is_as_sharp_as_a_mirror_and_unbounded() {
    assert_eq!(Opaque.lobe_width(), 0.0);
    assert!(!Opaque.is_diffuse());
    assert!(!Opaque.has_cone_bounds());
    let mut out = [0.0f32; 2];
    Opaque.cone_bounds(Vec3::Z, &[Cone::default(), Cone::new(Vec3::Z, 0.1)], &mut out);
    assert_eq!(out, [f32::INFINITY; 2], "+∞ bounds everything");
    assert_eq!(OpaqueDiffuse.lobe_width(), FRAC_PI_2, "diffuse by its own word");
    // Through a reference and behind `dyn`, the same answers.
    let by_ref: &dyn Brdf = &&RoughConductor::new(0.2, Vec3::ONE);
    assert_eq!((by_ref.lobe_width(), by_ref.has_cone_bounds()), (0.2, true));
}
