use kinedyn_core::spatial::{Force, Inertia, Mat3, Transform, Vec3};
use kinedyn_core::joint::axis_angle;
use std::hint::black_box;
use std::time::Instant;
fn t(label: &str, mut f: impl FnMut()) {
    let mut best = f64::INFINITY;
    for _ in 0..50 { let s = Instant::now(); for _ in 0..10000 { f(); } best = best.min(s.elapsed().as_nanos() as f64 / 10000.0); }
    println!("{label:20} {best:.2} ns");
}
fn main() {
    let x = Transform::new(axis_angle(&Vec3::new(0.3, 0.5, 0.8).normalize(), 0.7), Vec3::new(0.1, 0.2, 0.3));
    let i = Inertia::new(2.0, Vec3::new(0.1, 0.2, 0.3), Mat3::new(1.0, 0.1, 0.2, 0.1, 2.0, 0.3, 0.2, 0.3, 3.0));
    let f = Force::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0));
    let mut fs = [f; 6];
    t("act_inertia", || { black_box(black_box(&x).act_inertia(black_box(&i))); });
    t("rotated", || { black_box(black_box(&i).rotated(&black_box(&x).rot)); });
    t("translated", || { black_box(black_box(&i).translated(&black_box(&x).trans)); });
    t("act_force", || { black_box(black_box(&x).act_force(black_box(&f))); });
    t("act_force x6", || { let x = black_box(&x); for g in fs.iter_mut() { *g = x.act_force(g); } black_box(&fs); });
    t("mat3*mat3", || { black_box(black_box(x.rot) * black_box(x.rot)); });
    extra();
    extra2();
}
#[inline(never)]
fn mm_hand(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut c = [0.0; 9];
    for r in 0..3 { for k in 0..3 { c[3*r+k] = a[3*r]*b[k] + a[3*r+1]*b[3+k] + a[3*r+2]*b[6+k]; } }
    c
}
#[inline(never)]
fn mm_na(a: &Mat3, b: &Mat3) -> Mat3 { a * b }
pub fn extra() {
    let a = [1.0, 0.1, 0.2, 0.1, 2.0, 0.3, 0.2, 0.3, 3.0];
    let m = Mat3::new(1.0, 0.1, 0.2, 0.1, 2.0, 0.3, 0.2, 0.3, 3.0);
    t("mm_hand", || { black_box(mm_hand(black_box(&a), black_box(&a))); });
    t("mm_na", || { black_box(mm_na(black_box(&m), black_box(&m))); });
    t("empty", || { black_box(black_box(&a)); });
}
#[inline(never)]
fn rot_hand(r: &Mat3, i: &Inertia) -> Inertia {
    // columns of R: r.column(k); nalgebra is column-major: r[(row, col)]
    let (ixx, ixy, ixz, iyy, iyz, izz) = (i.i_o[(0, 0)], i.i_o[(0, 1)], i.i_o[(0, 2)], i.i_o[(1, 1)], i.i_o[(1, 2)], i.i_o[(2, 2)]);
    // A = R I  (row a of A = row a of R times I)
    let row = |a: usize| {
        let (r0, r1, r2) = (r[(a, 0)], r[(a, 1)], r[(a, 2)]);
        [r0 * ixx + r1 * ixy + r2 * ixz, r0 * ixy + r1 * iyy + r2 * iyz, r0 * ixz + r1 * iyz + r2 * izz]
    };
    let (a0, a1, a2) = (row(0), row(1), row(2));
    let e = |a: &[f64; 3], j: usize| a[0] * r[(j, 0)] + a[1] * r[(j, 1)] + a[2] * r[(j, 2)];
    let (xx, xy, xz, yy, yz, zz) = (e(&a0, 0), e(&a0, 1), e(&a0, 2), e(&a1, 1), e(&a1, 2), e(&a2, 2));
    Inertia::new(i.mass, r * i.h, Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz))
}
#[inline(never)]
fn rot_na(r: &Mat3, i: &Inertia) -> Inertia { i.rotated(r) }
pub fn extra2() {
    let x = Transform::new(axis_angle(&Vec3::new(0.3, 0.5, 0.8).normalize(), 0.7), Vec3::new(0.1, 0.2, 0.3));
    let i = Inertia::new(2.0, Vec3::new(0.1, 0.2, 0.3), Mat3::new(1.0, 0.1, 0.2, 0.1, 2.0, 0.3, 0.2, 0.3, 3.0));
    let a = rot_hand(&x.rot, &i); let b = rot_na(&x.rot, &i);
    assert!((a.i_o - b.i_o).abs().max() < 1e-14);
    t("rot_hand", || { black_box(rot_hand(black_box(&x.rot), black_box(&i))); });
    t("rot_na", || { black_box(rot_na(black_box(&x.rot), black_box(&i))); });
}
