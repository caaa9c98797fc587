//! Rigid-body dynamics of a serial chain (paper 002 §2.2): the links' inertial parameters as the
//! URDF gives them (`<inertial>`: mass, centre of mass, inertia about it; links rigidly attached
//! off the chain lumped into the chain link they hang from), the recursive Newton–Euler inverse
//! dynamics τ = M(q) q̈ + C(q, q̇) q̇ + g(q), the mass matrix and the gravity torques — generic over
//! the scalar ([`Real`]), so that the same code run on dual numbers ([`Dual`]) gives exact
//! derivatives (∂τ/∂q, ∂τ/∂q̇, ∂M/∂q) with no finite differences.
//!
//! Frames as in [`Chain`]: each chain link's frame is its parent's times the joint origin times
//! the joint's motion about (or along) its axis, the axis given in the link's own frame. The
//! recursion runs in the links' own frames (Craig, *Introduction to Robotics*, §6.5; Featherstone,
//! *Rigid Body Dynamics Algorithms*, §5.3), with gravity entering as an upward acceleration of the
//! root.
use crate::chain::{Chain, JointKind};
use glam::{DMat3, DVec3};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A link's inertial parameters in its frame (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkInertia {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the link frame (m).
    pub com: DVec3,
    /// Inertia about the centre of mass, in the link frame's axes (kg·m²).
    pub inertia: DMat3,
}

impl LinkInertia {
    /// No mass.
    pub const ZERO: LinkInertia = LinkInertia {
        mass: 0.0,
        com: DVec3::ZERO,
        inertia: DMat3::ZERO,
    };

    /// This body expressed in a frame where its own frame sits at rotation `r`, translation `t`.
    pub fn transformed(&self, r: DMat3, t: DVec3) -> LinkInertia {
        LinkInertia {
            mass: self.mass,
            com: r * self.com + t,
            inertia: r * self.inertia * r.transpose(),
        }
    }

    /// Two bodies in the same frame as one (the parallel-axis theorem).
    pub fn combined(&self, other: &LinkInertia) -> LinkInertia {
        let m = self.mass + other.mass;
        if m <= 0.0 {
            return LinkInertia::ZERO;
        }
        let com = (self.com * self.mass + other.com * other.mass) / m;
        let shift = |b: &LinkInertia| {
            let d = b.com - com;
            b.inertia + (DMat3::IDENTITY * d.length_squared() - outer(d, d)) * b.mass
        };
        LinkInertia {
            mass: m,
            com,
            inertia: shift(self) + shift(other),
        }
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A scalar the dynamics can run on: `f64`, or a dual number carrying derivatives.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// A constant.
    fn from_f64(v: f64) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// The value (without derivatives).
    fn value(self) -> f64;
}

impl Real for f64 {
    fn from_f64(v: f64) -> Self {
        v
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn value(self) -> f64 {
        self
    }
}

/// A dual number: a value and its derivatives with respect to `N` variables, over a scalar `T`
/// that may itself be a dual number (nested duals give second derivatives).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const N: usize, T = f64> {
    /// The value.
    pub v: T,
    /// The derivatives.
    pub d: [T; N],
}

impl<const N: usize, T: Real> Dual<N, T> {
    /// The `k`-th variable at value `v` (derivative 1 along `k`).
    pub fn variable(v: T, k: usize) -> Self {
        let mut d = [T::from_f64(0.0); N];
        if k < N {
            d[k] = T::from_f64(1.0);
        }
        Dual { v, d }
    }

    /// A constant.
    pub fn constant(v: T) -> Self {
        Dual {
            v,
            d: [T::from_f64(0.0); N],
        }
    }

    fn chain(self, v: T, slope: T) -> Self {
        Dual {
            v,
            d: self.d.map(|x| x * slope),
        }
    }
}

impl<const N: usize, T: Real> Add for Dual<N, T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Dual {
            v: self.v + o.v,
            d: std::array::from_fn(|k| self.d[k] + o.d[k]),
        }
    }
}

impl<const N: usize, T: Real> Sub for Dual<N, T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Dual {
            v: self.v - o.v,
            d: std::array::from_fn(|k| self.d[k] - o.d[k]),
        }
    }
}

impl<const N: usize, T: Real> Mul for Dual<N, T> {
    type Output = Self;
    // The product rule: d(uv) = u dv + v du.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, o: Self) -> Self {
        Dual {
            v: self.v * o.v,
            d: std::array::from_fn(|k| self.d[k] * o.v + self.v * o.d[k]),
        }
    }
}

impl<const N: usize, T: Real> Div for Dual<N, T> {
    type Output = Self;
    // The quotient rule.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Self) -> Self {
        let inv = T::from_f64(1.0) / o.v;
        let q = self.v * inv;
        Dual {
            v: q,
            d: std::array::from_fn(|k| (self.d[k] - q * o.d[k]) * inv),
        }
    }
}

impl<const N: usize, T: Real> Neg for Dual<N, T> {
    type Output = Self;
    fn neg(self) -> Self {
        Dual {
            v: -self.v,
            d: self.d.map(|x| -x),
        }
    }
}

impl<const N: usize, T: Real> Real for Dual<N, T> {
    fn from_f64(v: f64) -> Self {
        Dual::constant(T::from_f64(v))
    }
    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    fn cos(self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }
    fn value(self) -> f64 {
        self.v.value()
    }
}

/// A 3-vector over [`Real`].
#[derive(Clone, Copy, Debug)]
pub struct V3<T>(pub [T; 3]);

impl<T: Real> V3<T> {
    fn zero() -> Self {
        V3([T::from_f64(0.0); 3])
    }
    fn from(v: DVec3) -> Self {
        V3([T::from_f64(v.x), T::from_f64(v.y), T::from_f64(v.z)])
    }
    fn add(self, o: Self) -> Self {
        V3(std::array::from_fn(|k| self.0[k] + o.0[k]))
    }
    fn scale(self, s: T) -> Self {
        V3(self.0.map(|x| x * s))
    }
    fn dot(self, o: Self) -> T {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    fn cross(self, o: Self) -> Self {
        let [a, b, c] = self.0;
        let [x, y, z] = o.0;
        V3([b * z - c * y, c * x - a * z, a * y - b * x])
    }
}

/// A 3×3 matrix over [`Real`], row-major.
#[derive(Clone, Copy, Debug)]
struct M3<T>([[T; 3]; 3]);

impl<T: Real> M3<T> {
    fn from(m: DMat3) -> Self {
        // glam is column-major: m.col(j)[i] is row i, column j.
        M3(std::array::from_fn(|i| {
            std::array::from_fn(|j| T::from_f64(m.col(j)[i]))
        }))
    }
    /// `self · v`.
    fn mul(&self, v: V3<T>) -> V3<T> {
        V3(std::array::from_fn(|i| {
            self.0[i][0] * v.0[0] + self.0[i][1] * v.0[1] + self.0[i][2] * v.0[2]
        }))
    }
    /// `selfᵀ · v`.
    fn tmul(&self, v: V3<T>) -> V3<T> {
        V3(std::array::from_fn(|j| {
            self.0[0][j] * v.0[0] + self.0[1][j] * v.0[1] + self.0[2][j] * v.0[2]
        }))
    }
    fn matmul(&self, o: &M3<T>) -> M3<T> {
        M3(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                self.0[i][0] * o.0[0][j] + self.0[i][1] * o.0[1][j] + self.0[i][2] * o.0[2][j]
            })
        }))
    }
    /// The rotation by `angle` about the unit `axis` (Rodrigues).
    fn rotation(axis: DVec3, angle: T) -> M3<T> {
        let (s, c) = (angle.sin(), angle.cos());
        let one = T::from_f64(1.0);
        let t = one - c;
        let [x, y, z] = [axis.x, axis.y, axis.z].map(T::from_f64);
        M3([
            [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
            [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
            [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
        ])
    }
}

/// One chain link for the recursion.
#[derive(Clone, Debug)]
struct Body {
    /// The joint origin in the parent's frame.
    rotation: DMat3,
    translation: DVec3,
    /// The movable joint (index into q) and its kind and axis.
    joint: Option<(usize, JointKind, DVec3)>,
    inertia: LinkInertia,
}

/// The dynamics of a chain with its links' inertias.
#[derive(Clone, Debug)]
pub struct Dynamics {
    bodies: Vec<Body>,
    dof: usize,
    /// Gravity in the root frame (m/s²).
    pub gravity: DVec3,
}

impl Dynamics {
    /// The dynamics of `chain` with `inertias[i]` for chain link `i` (`None`: massless), gravity
    /// (0, 0, −9.81) in the root frame.
    pub fn new(chain: &Chain, inertias: &[Option<LinkInertia>]) -> Self {
        let bodies = chain
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| Body {
                rotation: DMat3::from_quat(l.origin.rotation),
                translation: l.origin.translation,
                joint: l
                    .joint
                    .and_then(|j| chain.joints.get(j).map(|jt| (j, jt.kind, jt.axis))),
                inertia: inertias.get(i).copied().flatten().unwrap_or(LinkInertia::ZERO),
            })
            .collect();
        Dynamics {
            bodies,
            dof: chain.dof(),
            gravity: DVec3::new(0.0, 0.0, -9.81),
        }
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// The total mass (kg).
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.inertia.mass).sum()
    }

    /// Recursive Newton–Euler: the joint torques (forces for prismatic joints) that give
    /// accelerations `qdd` at `q`, `qd`, with gravity scaled by `g_scale` (1 for the real
    /// torques, 0 without gravity). Missing values count as zero.
    pub fn rnea_with<T: Real>(&self, q: &[T], qd: &[T], qdd: &[T], g_scale: f64) -> Vec<T> {
        let zero = T::from_f64(0.0);
        let n = self.bodies.len();
        let at = |v: &[T], j: usize| v.get(j).copied().unwrap_or(zero);
        // Forward: velocities and accelerations in each link's own frame.
        let mut rot: Vec<M3<T>> = Vec::with_capacity(n);
        let mut pos: Vec<V3<T>> = Vec::with_capacity(n);
        let mut forces: Vec<(V3<T>, V3<T>)> = Vec::with_capacity(n);
        let mut w = V3::<T>::zero();
        let mut wd = V3::<T>::zero();
        let mut a = V3::from(-self.gravity * g_scale);
        for b in &self.bodies {
            let origin = M3::from(b.rotation);
            let mut r = origin;
            let mut p = V3::from(b.translation);
            // Parent quantities seen at this link's origin, in the parent frame.
            let a_here = a.add(wd.cross(p)).add(w.cross(w.cross(p)));
            let (w_i, wd_i, a_i);
            match b.joint {
                Some((j, JointKind::Prismatic, axis)) => {
                    let z = V3::from(axis);
                    let (qj, qdj, qddj) = (at(q, j), at(qd, j), at(qdd, j));
                    // Translation along the axis, given in the link frame = the origin frame.
                    let shift = origin.mul(z.scale(qj));
                    p = p.add(shift);
                    let a_here = a.add(wd.cross(p)).add(w.cross(w.cross(p)));
                    w_i = origin.tmul(w);
                    wd_i = origin.tmul(wd);
                    a_i = origin
                        .tmul(a_here)
                        .add(w_i.cross(z.scale(qdj)).scale(T::from_f64(2.0)))
                        .add(z.scale(qddj));
                }
                Some((j, _, axis)) => {
                    let z = V3::from(axis);
                    let (qj, qdj, qddj) = (at(q, j), at(qd, j), at(qdd, j));
                    r = origin.matmul(&M3::rotation(axis, qj));
                    let w_p = r.tmul(w);
                    w_i = w_p.add(z.scale(qdj));
                    wd_i = r.tmul(wd).add(z.scale(qddj)).add(w_p.cross(z.scale(qdj)));
                    a_i = r.tmul(a_here);
                }
                None => {
                    w_i = origin.tmul(w);
                    wd_i = origin.tmul(wd);
                    a_i = origin.tmul(a_here);
                }
            }
            let c = V3::from(b.inertia.com);
            let inertia = M3::from(b.inertia.inertia);
            let a_c = a_i.add(wd_i.cross(c)).add(w_i.cross(w_i.cross(c)));
            let f = a_c.scale(T::from_f64(b.inertia.mass));
            let nn = inertia.mul(wd_i).add(w_i.cross(inertia.mul(w_i)));
            forces.push((f, nn));
            rot.push(r);
            pos.push(p);
            (w, wd, a) = (w_i, wd_i, a_i);
        }
        // Backward: forces and moments, each link's from its children's.
        let mut tau = vec![zero; self.dof];
        let mut f_child = V3::<T>::zero();
        let mut n_child = V3::<T>::zero();
        for i in (0..n).rev() {
            let b = &self.bodies[i];
            let (fi, ni) = forces[i];
            let c = V3::from(b.inertia.com);
            // The child's force and moment in this frame, and where it acts.
            let (f_in, n_in) = if i + 1 < n {
                (
                    rot[i + 1].mul(f_child),
                    rot[i + 1]
                        .mul(n_child)
                        .add(pos[i + 1].cross(rot[i + 1].mul(f_child))),
                )
            } else {
                (V3::zero(), V3::zero())
            };
            let f = fi.add(f_in);
            let nm = ni.add(n_in).add(c.cross(fi));
            if let Some((j, kind, axis)) = b.joint {
                let z = V3::from(axis);
                if j < tau.len() {
                    tau[j] = if kind == JointKind::Prismatic {
                        f.dot(z)
                    } else {
                        nm.dot(z)
                    };
                }
            }
            f_child = f;
            n_child = nm;
        }
        tau
    }

    /// τ = M(q) q̈ + C(q, q̇) q̇ + g(q).
    pub fn inverse_dynamics(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
        self.rnea_with(q, qd, qdd, 1.0)
    }

    /// The gravity torques g(q).
    pub fn gravity_torques<T: Real>(&self, q: &[T]) -> Vec<T> {
        self.rnea_with(q, &[], &[], 1.0)
    }

    /// The mass matrix M(q), row by row (one recursion per column, no velocity, no gravity).
    pub fn mass_matrix<T: Real>(&self, q: &[T]) -> Vec<Vec<T>> {
        let n = self.dof;
        let mut m = vec![vec![T::from_f64(0.0); n]; n];
        for c in 0..n {
            let mut e = vec![T::from_f64(0.0); n];
            e[c] = T::from_f64(1.0);
            let col = self.rnea_with(q, &[], &e, 0.0);
            for r in 0..n {
                m[r][c] = col[r];
            }
        }
        m
    }

    /// The kinetic energy ½ q̇ᵀ M(q) q̇ (one recursion: M(q) q̇ is the torque for acceleration
    /// q̇ at rest without gravity).
    pub fn kinetic<T: Real>(&self, q: &[T], qd: &[T]) -> T {
        let p = self.rnea_with(q, &[], qd, 0.0);
        let mut e = T::from_f64(0.0);
        for (a, b) in p.iter().zip(qd) {
            e = e + *a * *b;
        }
        e * T::from_f64(0.5)
    }

    /// The generalised momentum ∂L/∂q̇ = M(q) q̇.
    pub fn momentum<T: Real>(&self, q: &[T], qd: &[T]) -> Vec<T> {
        self.rnea_with(q, &[], qd, 0.0)
    }

    /// The potential energy of gravity, −Σ mᵢ g·cᵢ (J), with the root's origin as zero.
    pub fn potential<T: Real>(&self, q: &[T]) -> T {
        let zero = T::from_f64(0.0);
        let mut r_acc: M3<T> = M3::from(DMat3::IDENTITY);
        let mut p_acc = V3::<T>::zero();
        let mut v = zero;
        let g = V3::from(self.gravity);
        for b in &self.bodies {
            let origin = M3::from(b.rotation);
            let mut p = V3::from(b.translation);
            let mut r = origin;
            match b.joint {
                Some((j, JointKind::Prismatic, axis)) => {
                    p = p.add(origin.mul(V3::from(axis).scale(q.get(j).copied().unwrap_or(zero))));
                }
                Some((j, _, axis)) => {
                    r = origin.matmul(&M3::rotation(axis, q.get(j).copied().unwrap_or(zero)));
                }
                None => {}
            }
            p_acc = p_acc.add(r_acc.mul(p));
            r_acc = r_acc.matmul(&r);
            let com = p_acc.add(r_acc.mul(V3::from(b.inertia.com)));
            v = v - g.dot(com) * T::from_f64(b.inertia.mass);
        }
        v
    }

    /// τ and its exact derivatives ∂τ/∂q and ∂τ/∂q̇ (row i, column j: ∂τᵢ/∂xⱼ), by dual
    /// numbers; `None` for a chain of more than 8 joints.
    #[allow(clippy::type_complexity)]
    pub fn inverse_dynamics_derivatives(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Option<(Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>)> {
        let n = self.dof;
        if n > 8 {
            return None;
        }
        let qq: Vec<Dual<16>> = (0..n)
            .map(|j| Dual::variable(q.get(j).copied().unwrap_or(0.0), j))
            .collect();
        let vv: Vec<Dual<16>> = (0..n)
            .map(|j| Dual::variable(qd.get(j).copied().unwrap_or(0.0), 8 + j))
            .collect();
        let aa: Vec<Dual<16>> = (0..n)
            .map(|j| Dual::constant(qdd.get(j).copied().unwrap_or(0.0)))
            .collect();
        let tau = self.rnea_with(&qq, &vv, &aa, 1.0);
        let value = tau.iter().map(|t| t.v).collect();
        let dq = tau.iter().map(|t| (0..n).map(|j| t.d[j]).collect()).collect();
        let dv = tau.iter().map(|t| (0..n).map(|j| t.d[8 + j]).collect()).collect();
        Some((value, dq, dv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;
    use std::path::Path;

    const L1: f64 = 0.9;
    const LC1: f64 = 0.4;
    const LC2: f64 = 0.35;
    const M1: f64 = 7.0;
    const M2: f64 = 4.0;
    const I1: f64 = 0.3;
    const I2: f64 = 0.12;

    /// A two-link arm in the x–z plane (joints about −y, so that positive angles lift it), with
    /// a fixed tool link carrying a mass of its own, as URDF text.
    fn planar() -> Dynamics {
        let urdf = format!(
            r#"<robot name="planar">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="{LC1} 0 0"/><mass value="{M1}"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="{I1}" iyz="0" izz="0.02"/></inertial></link>
  <link name="l2"><inertial><origin xyz="{LC2} 0 0"/><mass value="{M2}"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="{I2}" iyz="0" izz="0.02"/></inertial></link>
  <link name="tool0"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="{L1} 0 0"/><axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="t" type="fixed"><parent link="l2"/><child link="tool0"/><origin xyz="0.7 0 0"/></joint>
</robot>"#
        );
        let model = crate::load_urdf_str(&urdf, Path::new("planar.urdf"), &BTreeMap::new(), None).unwrap();
        Dynamics::new(&model.chain, &model.inertia)
    }

    /// The textbook equations of the two-link arm (Spong, *Robot Modeling and Control*, §7.4).
    fn textbook(q: [f64; 2], v: [f64; 2], a: [f64; 2]) -> [f64; 2] {
        let g = 9.81;
        let c2 = q[1].cos();
        let m11 = I1 + I2 + M1 * LC1 * LC1 + M2 * (L1 * L1 + LC2 * LC2 + 2.0 * L1 * LC2 * c2);
        let m12 = I2 + M2 * (LC2 * LC2 + L1 * LC2 * c2);
        let m22 = I2 + M2 * LC2 * LC2;
        let h = -M2 * L1 * LC2 * q[1].sin();
        let g1 = (M1 * LC1 + M2 * L1) * g * q[0].cos() + M2 * LC2 * g * (q[0] + q[1]).cos();
        let g2 = M2 * LC2 * g * (q[0] + q[1]).cos();
        [
            m11 * a[0] + m12 * a[1] + h * (2.0 * v[0] * v[1] + v[1] * v[1]) + g1,
            m12 * a[0] + m22 * a[1] - h * v[0] * v[0] + g2,
        ]
    }

    fn states(n: usize, dof: usize) -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut r = |s: f64| -> Vec<f64> { (0..dof).map(|_| rng.random_range(-s..s)).collect() };
        (0..n).map(|_| (r(3.0), r(3.0), r(10.0))).collect()
    }

    #[test]
    fn the_two_link_arm_matches_the_textbook_equations() {
        let d = planar();
        assert_eq!(d.dof(), 2);
        assert!((d.mass() - M1 - M2).abs() < 1e-12);
        for (q, v, a) in states(200, 2) {
            let tau = d.inverse_dynamics(&q, &v, &a);
            let want = textbook([q[0], q[1]], [v[0], v[1]], [a[0], a[1]]);
            for k in 0..2 {
                assert!(
                    (tau[k] - want[k]).abs() <= 1e-10 * want[k].abs().max(1.0),
                    "{tau:?} vs {want:?}"
                );
            }
        }
    }

    #[test]
    fn lumped_fixed_links_move_the_mass_where_the_urdf_puts_it() {
        // A fixed child with mass at the tip: the same as one link with both masses combined.
        let a = LinkInertia {
            mass: 2.0,
            com: DVec3::new(0.1, 0.0, 0.0),
            inertia: DMat3::from_diagonal(DVec3::new(0.01, 0.02, 0.03)),
        };
        let b = LinkInertia {
            mass: 3.0,
            com: DVec3::new(0.0, 0.2, 0.0),
            inertia: DMat3::from_diagonal(DVec3::new(0.04, 0.05, 0.06)),
        };
        let c = a.combined(&b);
        assert!((c.mass - 5.0).abs() < 1e-15);
        assert!((c.com - DVec3::new(0.04, 0.12, 0.0)).length() < 1e-15);
        // The inertia about the origin is the sum of each about the origin.
        let about_origin = |x: &LinkInertia| {
            x.inertia + (DMat3::IDENTITY * x.com.length_squared() - outer(x.com, x.com)) * x.mass
        };
        let sum = about_origin(&a) + about_origin(&b);
        let got = about_origin(&c);
        assert!((sum - got).to_cols_array().iter().all(|e| e.abs() < 1e-14));
    }

    /// A 6-joint arm with every kind of offset: the UR10's kinematics with made-up inertias.
    fn six() -> Dynamics {
        let mut links = String::new();
        let mut joints = String::new();
        let origins = [
            "0 0 0.1273",
            "0 0.220941 0",
            "0 -0.1719 0.612",
            "0 0 0.5723",
            "0 0.1149 0",
            "0 0 0.1157",
        ];
        let axes = ["0 0 1", "0 1 0", "0 1 0", "0 1 0", "0 0 1", "0 1 0"];
        for k in 0..6 {
            links += &format!(
                r#"<link name="l{k}"><inertial><origin xyz="0.0{k} 0.01 0.{}" rpy="0.1 0.2 0.{k}"/><mass value="{}"/><inertia ixx="0.{}" ixy="0.001" ixz="-0.002" iyy="0.05" iyz="0.003" izz="0.04"/></inertial></link>"#,
                k + 1,
                10.0 - k as f64,
                k + 3
            );
            let parent = if k == 0 {
                "base".to_string()
            } else {
                format!("l{}", k - 1)
            };
            joints += &format!(
                r#"<joint name="j{k}" type="revolute"><parent link="{parent}"/><child link="l{k}"/><origin xyz="{}" rpy="0 {} 0"/><axis xyz="{}"/><limit lower="-6" upper="6" effort="100" velocity="3"/></joint>"#,
                origins[k],
                if k == 1 || k == 3 {
                    std::f64::consts::FRAC_PI_2
                } else {
                    0.0
                },
                axes[k]
            );
        }
        let urdf = format!(
            r#"<robot name="six"><link name="base"/>{links}<link name="tool0"><inertial><origin xyz="0 0 0.05"/><mass value="1.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>{joints}<joint name="t" type="fixed"><parent link="l5"/><child link="tool0"/><origin xyz="0 0.0922 0" rpy="-1.5707963 0 0"/></joint></robot>"#
        );
        let model = crate::load_urdf_str(&urdf, Path::new("six.urdf"), &BTreeMap::new(), None).unwrap();
        Dynamics::new(&model.chain, &model.inertia)
    }

    #[test]
    fn the_mass_matrix_is_symmetric_positive_definite_and_tau_is_linear_in_acceleration() {
        let d = six();
        for (q, v, a) in states(50, 6) {
            let m = d.mass_matrix(&q);
            for (i, row) in m.iter().enumerate() {
                assert!(row[i] > 0.0);
                for (j, x) in row.iter().enumerate() {
                    assert!((x - m[j][i]).abs() < 1e-12, "M not symmetric");
                }
            }
            // Cholesky succeeds.
            let mut l = [[0.0f64; 6]; 6];
            for i in 0..6 {
                for j in 0..=i {
                    let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
                    if i == j {
                        assert!(m[i][i] - s > 0.0, "M not positive definite");
                        l[i][j] = (m[i][i] - s).sqrt();
                    } else {
                        l[i][j] = (m[i][j] - s) / l[j][j];
                    }
                }
            }
            let bias = d.inverse_dynamics(&q, &v, &[0.0; 6]);
            let tau = d.inverse_dynamics(&q, &v, &a);
            for i in 0..6 {
                let ma: f64 = (0..6).map(|j| m[i][j] * a[j]).sum();
                assert!((tau[i] - bias[i] - ma).abs() < 1e-10 * tau[i].abs().max(1.0));
            }
        }
    }

    #[test]
    fn gravity_torques_are_the_gradient_of_the_potential_and_power_balances() {
        let d = six();
        for (q, v, _) in states(50, 6) {
            // g(q) = ∂V/∂q, by dual numbers on V.
            let qd: Vec<Dual<6>> = (0..6).map(|j| Dual::variable(q[j], j)).collect();
            let pot = d.potential(&qd);
            let g = d.gravity_torques(&q);
            for (j, gj) in g.iter().enumerate() {
                assert!(
                    (pot.d[j] - gj).abs() < 1e-10 * gj.abs().max(1.0),
                    "{j}: {} vs {gj}",
                    pot.d[j]
                );
            }
            // q̇ᵀ(C q̇) = ½ q̇ᵀ Ṁ q̇ (C q̇ = rnea(q, q̇, 0) − g), Ṁ = Σ ∂M/∂q_k q̇_k.
            let c = d.rnea_with(&q, &v, &[], 0.0);
            let lhs: f64 = (0..6).map(|i| v[i] * c[i]).sum();
            let qv: Vec<Dual<1>> = (0..6).map(|j| Dual { v: q[j], d: [v[j]] }).collect();
            let mdot = d.mass_matrix(&qv);
            let rhs: f64 = 0.5
                * (0..6)
                    .map(|i| (0..6).map(|j| v[i] * mdot[i][j].d[0] * v[j]).sum::<f64>())
                    .sum::<f64>();
            assert!((lhs - rhs).abs() < 1e-9 * lhs.abs().max(1.0), "{lhs} vs {rhs}");
        }
    }

    #[test]
    fn derivatives_by_dual_numbers_match_central_differences() {
        let d = six();
        for (q, v, a) in states(10, 6) {
            let (tau, dq, dv) = d.inverse_dynamics_derivatives(&q, &v, &a).unwrap();
            assert_eq!(tau, d.inverse_dynamics(&q, &v, &a));
            let h = 1e-6;
            for j in 0..6 {
                let bump = |x: &[f64], s: f64| -> Vec<f64> {
                    let mut y = x.to_vec();
                    y[j] += s;
                    y
                };
                let fq: Vec<f64> = d
                    .inverse_dynamics(&bump(&q, h), &v, &a)
                    .iter()
                    .zip(d.inverse_dynamics(&bump(&q, -h), &v, &a))
                    .map(|(p, m)| (p - m) / (2.0 * h))
                    .collect();
                let fv: Vec<f64> = d
                    .inverse_dynamics(&q, &bump(&v, h), &a)
                    .iter()
                    .zip(d.inverse_dynamics(&q, &bump(&v, -h), &a))
                    .map(|(p, m)| (p - m) / (2.0 * h))
                    .collect();
                for i in 0..6 {
                    assert!(
                        (dq[i][j] - fq[i]).abs() < 1e-5 * fq[i].abs().max(1.0),
                        "dτ{i}/dq{j}"
                    );
                    assert!(
                        (dv[i][j] - fv[i]).abs() < 1e-5 * fv[i].abs().max(1.0),
                        "dτ{i}/dv{j}"
                    );
                }
            }
        }
    }
}
