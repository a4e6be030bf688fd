//! Geometric stiffening of the spatial beam against the planar beam's, element for element
//! (`spatial_beam/stiffening.rs` extends `planar_beam/stiffening.rs` to both bending planes):
//! a deformation in the x–y plane has the planar beam's strain energy, the same deformation
//! turned into the x–z plane (v → w, θz → −θy) too, and one in both planes at once the
//! planar stiffening energy of √2 times the slopes (the axial strain adds ½⟨v'²⟩ and ½⟨w'²⟩).
//! The tangents of both are checked against finite differences elsewhere
//! (`spatial_jacobians.rs`, `planar_beam_element.rs`).

use crate::mechanics::beam::planar_beam::{BeamOptions, PlanarBeam, FLEX as PFLEX};
use crate::mechanics::beam::section::Section;
use crate::mechanics::beam::spatial_beam::{InertiaModel, SpatialBeam, SpatialBeamProps};
use crate::mechanics::beam::spatial_element::{NODE_DOFS, TY, TZ, U, V, W};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::FloatingFrame;
use nalgebra::DVector;

/// The planar and the spatial beam of one geometry (4 elements, 0.8 m, aluminium-like), with
/// geometric stiffening; the spatial section has I_y = I_z = J.
fn beams(frame: FloatingFrame) -> (PlanarBeam, SpatialBeam) {
    let section = Section::rectangle(0.02, 0.01);
    let options = BeamOptions {
        geometric_stiffening: true,
        ..BeamOptions::default()
    };
    let planar =
        PlanarBeam::with_options("p", 0.8, 4, frame, 2700.0, 7e10, section, 0.0, 0.0, options);
    let j = section.second_moment;
    let props = SpatialBeamProps {
        length: 0.8,
        elements: 4,
        frame,
        rho: 2700.0,
        e: 7e10,
        g: 2.6e10,
        section: SpatialSection::given(section.area, j, j, 2.0 * j),
        rayleigh_alpha: 0.0,
        rayleigh_beta: 0.0,
        inertia: InertiaModel::Full,
    };
    let mut spatial = SpatialBeam::new("s", &props);
    spatial.set_geometric_stiffening(true);
    (planar, spatial)
}

/// A planar deformation (kept coordinates) put on the spatial beam: u and (v, θz) in the
/// x–y plane times `in_plane`, (w, −θy) in the x–z plane times `out_of_plane`.
fn spatial_coordinates(
    p: &PlanarBeam,
    s: &SpatialBeam,
    qf: &DVector<f64>,
    in_plane: f64,
    out_of_plane: f64,
) -> DVector<f64> {
    let mut f = DVector::zeros(s.nflex());
    for (i, &full) in p.kept.iter().enumerate() {
        let node = NODE_DOFS * (full / 3);
        let put = |f: &mut DVector<f64>, dof: usize, x: f64| {
            let k = s
                .flex_index(node + dof)
                .expect("3D keeps the planar coordinates");
            f[k] += x;
        };
        match full % 3 {
            0 => put(&mut f, U, qf[i]),
            1 => {
                put(&mut f, V, in_plane * qf[i]);
                put(&mut f, W, out_of_plane * qf[i]);
            }
            _ => {
                put(&mut f, TZ, in_plane * qf[i]);
                put(&mut f, TY, -out_of_plane * qf[i]);
            }
        }
    }
    f
}

#[test]
fn stiffening_energy_is_the_planar_one_in_either_plane_and_adds_up_in_both() {
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let (p, s) = beams(frame);
        let n = p.nflex();
        // axial 1e-4 of the element length, slopes up to about 0.1
        let qf = DVector::from_fn(n, |i, _| {
            let x = ((i * 7919 % 23) as f64 / 11.0) - 1.0;
            match p.kept[i] % 3 {
                0 => 2e-5 * x,
                1 => 0.02 * x,
                _ => 0.1 * x,
            }
        });
        let planar = |q: &DVector<f64>| {
            let mut z = DVector::zeros(PFLEX + n);
            z.rows_mut(PFLEX, n).copy_from(q);
            let full = p.strain_energy(&z);
            (full, full - 0.5 * q.dot(&p.kff.mul_vec(&q.as_view())))
        };
        let spatial = |f: &DVector<f64>| {
            let full = s.strain_energy(f);
            (full, full - 0.5 * f.dot(&(&s.kff * f)))
        };
        let (ep, gp) = planar(&qf);
        let (exy, gxy) = spatial(&spatial_coordinates(&p, &s, &qf, 1.0, 0.0));
        let (exz, gxz) = spatial(&spatial_coordinates(&p, &s, &qf, 0.0, 1.0));
        // both planes at once: the planar stiffening energy of √2 times the transverse field
        let mut scaled = qf.clone();
        for (i, &full) in p.kept.iter().enumerate() {
            if full % 3 != 0 {
                scaled[i] *= std::f64::consts::SQRT_2;
            }
        }
        let (_, g2p) = planar(&scaled);
        let (_, gboth) = spatial(&spatial_coordinates(&p, &s, &qf, 1.0, 1.0));
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        println!(
            "{frame:?}: strain energy {ep:.6e} J (stiffening {gp:.3e}); x–y {:.1e}, x–z {:.1e}, \
             both planes {:.1e} relative",
            rel(exy, ep).max(rel(gxy, gp)),
            rel(exz, ep).max(rel(gxz, gp)),
            rel(gboth, g2p)
        );
        assert!(
            gp > 1e-3 * ep,
            "the stiffening energy is a measurable share: {gp:e}"
        );
        for (a, b) in [(exy, ep), (gxy, gp), (exz, ep), (gxz, gp), (gboth, g2p)] {
            assert!(rel(a, b) < 1e-12, "{a:e} against {b:e}");
        }
    }
}
