//! A spatial beam's construction: the full-beam shape integrals (4-point Gauss), the frame's
//! boundary conditions, and a beam from nodal matrices (a matrix file's, frozen inertia).

use super::*;

impl SpatialBeam {
    /// Builds the whole beam of `props` (one floating frame).
    pub fn new(name: &str, props: &SpatialBeamProps) -> SpatialBeam {
        SpatialBeam::part_of(props, name, props.length)
    }

    /// One floating frame of a beam: the whole beam, or one of its substructures, named
    /// `name`, of length `length`, with `props.elements` elements (as
    /// `PlanarBeam::part_of`; substructures are welded flange b to
    /// flange a of the next by the multibody layer, paper §3.4).
    pub fn part_of(props: &SpatialBeamProps, name: &str, length: f64) -> SpatialBeam {
        let props = SpatialBeamProps {
            length,
            ..props.clone()
        };
        let full = full_integrals(&props);
        let kept = kept_coordinates(props.frame, props.elements);
        let pick_cols = |m: &DMatrix<f64>| m.select_columns(kept.iter());
        let pick = |m: &DMatrix<f64>| m.select_rows(kept.iter()).select_columns(kept.iter());
        let mu = props.rho * props.section.area;
        let integrals = ShapeIntegrals {
            sbar: pick_cols(&full.sbar),
            d: pick_cols(&full.d),
            mij: std::array::from_fn(|k| pick(&full.mij[k])),
            twist: full.twist.select_rows(kept.iter()),
            j0: full.j0,
            rotary: props.rho * props.section.polar_moment * length,
        };
        let mut beam = SpatialBeam::from_nodal_matrices(
            name,
            length,
            props.elements,
            props.frame,
            &full.mass,
            &full.stiffness,
            props.rayleigh_alpha,
            props.rayleigh_beta,
        );
        beam.mass = mu * length;
        beam.integrals = Some(integrals);
        beam.inertia = props.inertia;
        beam
    }

    /// A beam from nodal mass and stiffness matrices (6 per node, `elements` equal elements
    /// over `length`), e.g. condensed by another FE tool: constant inertia
    /// ([`InertiaModel::Frozen`]; no shape integrals), K_ff and m_ff the kept blocks.
    pub fn from_nodal_matrices(
        name: &str,
        length: f64,
        elements: usize,
        frame: FloatingFrame,
        mass: &DMatrix<f64>,
        stiffness: &DMatrix<f64>,
        rayleigh_alpha: f64,
        rayleigh_beta: f64,
    ) -> SpatialBeam {
        let kept = kept_coordinates(frame, elements);
        let pick = |m: &DMatrix<f64>| m.select_rows(kept.iter()).select_columns(kept.iter());
        let x: Vec<f64> = (0..=elements)
            .map(|j| length * j as f64 / elements as f64)
            .collect();
        let undeformed = UndeformedInertia::from_nodal_mass(mass, &x, &kept);
        let mff = pick(mass);
        let kff = pick(stiffness);
        let dff = &kff * rayleigh_beta;
        let mut beam = SpatialBeam {
            name: name.to_string(),
            length,
            elements,
            frame,
            inertia: InertiaModel::Frozen,
            rayleigh_alpha,
            rayleigh_beta,
            mass: undeformed.mtt.trace() / 3.0,
            integrals: None,
            undeformed,
            mff,
            ea: stiffness[(U, U)] * length / elements as f64,
            kff,
            dff,
            geometric_stiffening: false,
            strain: stiffening::StrainRows::new(length, elements, &kept),
            flange_a: SpatialPointMap {
                s0: Vector3::zeros(),
                sp: DMatrix::zeros(3, kept.len()),
                sphi: DMatrix::zeros(3, kept.len()),
            },
            flange_b: SpatialPointMap {
                s0: Vector3::zeros(),
                sp: DMatrix::zeros(3, 0),
                sphi: DMatrix::zeros(3, 0),
            },
            kept,
        };
        beam.flange_a = beam.point_map(0.0);
        beam.flange_b = beam.point_map(length);
        beam
    }
}

/// Integrals over all nodes, before the boundary conditions; and the nodal mass and stiffness.
pub(super) struct FullIntegrals {
    sbar: DMatrix<f64>,
    d: DMatrix<f64>,
    mij: [DMatrix<f64>; 6],
    twist: DVector<f64>,
    j0: f64,
    mass: DMatrix<f64>,
    stiffness: DMatrix<f64>,
}

pub(super) fn full_integrals(p: &SpatialBeamProps) -> FullIntegrals {
    let n = p.elements;
    let n_full = NODE_DOFS * (n + 1);
    let l = p.length / n as f64;
    let mu = p.rho * p.section.area;
    let rho_ip = p.rho * p.section.polar_moment;
    let mut out = FullIntegrals {
        sbar: DMatrix::zeros(3, n_full),
        d: DMatrix::zeros(3, n_full),
        mij: std::array::from_fn(|_| DMatrix::zeros(n_full, n_full)),
        twist: DVector::zeros(n_full),
        j0: 0.0,
        mass: DMatrix::zeros(n_full, n_full),
        stiffness: DMatrix::zeros(n_full, n_full),
    };
    let s = &p.section;
    let ke = spatial_element::stiffness(
        p.e * s.area,
        p.g * s.torsion_constant,
        p.e * s.iy,
        p.e * s.iz,
        l,
    );
    let me = spatial_element::mass(mu, rho_ip, l);
    for j in 0..n {
        let o = NODE_DOFS * j; // connectivity B_j (3D paper eq. (31), 6 per node)
        for &(xi, wgt) in &GAUSS_4 {
            let sh = spatial_element::shape(xi, l);
            let tw = spatial_element::twist(xi);
            let dm = mu * l * wgt;
            let x0 = (j as f64 + xi) * l;
            out.j0 += dm * x0 * x0;
            for a in 0..ELEMENT_DOFS {
                out.twist[o + a] += rho_ip * l * wgt * tw[a];
                for i in 0..3 {
                    out.sbar[(i, o + a)] += dm * sh[i][a];
                    out.d[(i, o + a)] += dm * x0 * sh[i][a];
                }
                for b in 0..ELEMENT_DOFS {
                    for (k, &(pi, pj)) in PAIRS.iter().enumerate() {
                        out.mij[k][(o + a, o + b)] += dm * sh[pi][a] * sh[pj][b];
                    }
                }
            }
        }
        for a in 0..ELEMENT_DOFS {
            for b in 0..ELEMENT_DOFS {
                out.mass[(o + a, o + b)] += me[a][b];
                out.stiffness[(o + a, o + b)] += ke[a][b];
            }
        }
    }
    out
}
