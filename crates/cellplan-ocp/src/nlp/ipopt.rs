//! IPOPT itself (the COIN-OR library, through its C interface) on any [`Nlp`]: the reference
//! the interior-point solver of [`super::ipm`] is measured against on the same problem with
//! the same derivatives. Opt-in (`--features ipopt`): it links the system's `libipopt`
//! (Debian: `apt-get install coinor-libipopt-dev`, IPOPT 3.11 with MUMPS); the default build
//! needs nothing outside Rust.
//!
//! IPOPT fixes the sparsity structure once ([`Structure::of`]); an entry outside it later ends
//! the solve with [`Status::NumericalFailure`] rather than being dropped.
use super::structure::{Structure, stacked_bounds, stacked_constraints, stacked_jacobian};
use super::{Nlp, Status, Triplets};
use std::ffi::{CString, c_char, c_int, c_void};

type Bool = c_int;
type Index = c_int;
type EvalF = extern "C" fn(Index, *mut f64, Bool, *mut f64, *mut c_void) -> Bool;
type EvalGradF = extern "C" fn(Index, *mut f64, Bool, *mut f64, *mut c_void) -> Bool;
type EvalG = extern "C" fn(Index, *mut f64, Bool, Index, *mut f64, *mut c_void) -> Bool;
type EvalJacG =
    extern "C" fn(Index, *mut f64, Bool, Index, Index, *mut Index, *mut Index, *mut f64, *mut c_void) -> Bool;
type EvalH = extern "C" fn(
    Index,
    *mut f64,
    Bool,
    f64,
    Index,
    *mut f64,
    Bool,
    Index,
    *mut Index,
    *mut Index,
    *mut f64,
    *mut c_void,
) -> Bool;
type Intermediate =
    extern "C" fn(Index, Index, f64, f64, f64, f64, f64, f64, f64, f64, Index, *mut c_void) -> Bool;

#[link(name = "ipopt")]
unsafe extern "C" {
    fn CreateIpoptProblem(
        n: Index,
        x_l: *mut f64,
        x_u: *mut f64,
        m: Index,
        g_l: *mut f64,
        g_u: *mut f64,
        nele_jac: Index,
        nele_hess: Index,
        index_style: Index,
        eval_f: EvalF,
        eval_g: EvalG,
        eval_grad_f: EvalGradF,
        eval_jac_g: EvalJacG,
        eval_h: EvalH,
    ) -> *mut c_void;
    fn FreeIpoptProblem(p: *mut c_void);
    fn AddIpoptStrOption(p: *mut c_void, key: *const c_char, val: *const c_char) -> Bool;
    fn AddIpoptNumOption(p: *mut c_void, key: *const c_char, val: f64) -> Bool;
    fn AddIpoptIntOption(p: *mut c_void, key: *const c_char, val: c_int) -> Bool;
    fn SetIntermediateCallback(p: *mut c_void, cb: Intermediate) -> Bool;
    #[allow(clippy::too_many_arguments)]
    fn IpoptSolve(
        p: *mut c_void,
        x: *mut f64,
        g: *mut f64,
        obj: *mut f64,
        mult_g: *mut f64,
        mult_x_l: *mut f64,
        mult_x_u: *mut f64,
        user: *mut c_void,
    ) -> c_int;
}

/// What IPOPT is told (its option names; the rest stay IPOPT's defaults).
#[derive(Clone, Debug)]
pub struct IpoptOptions {
    /// `tol`.
    pub tol: f64,
    /// `max_iter`.
    pub max_iter: usize,
    /// `bound_relax_factor` (IPOPT's default is 1e-8; 0 keeps every bound exactly, as the
    /// CasADi reference runs in `bench/ocp` do).
    pub bound_relax_factor: f64,
    /// `print_level` (0 silent).
    pub print_level: i32,
}

impl Default for IpoptOptions {
    fn default() -> Self {
        IpoptOptions {
            tol: 1e-10,
            max_iter: 3000,
            bound_relax_factor: 0.0,
            print_level: 0,
        }
    }
}

/// IPOPT's outcome.
#[derive(Clone, Debug)]
pub struct IpoptSolution {
    /// IPOPT's return code mapped to the solver's statuses (an entry outside the fixed
    /// structure, an evaluation error and IPOPT's internal failures are `NumericalFailure`).
    pub status: Status,
    /// IPOPT's `ApplicationReturnStatus` as it gave it.
    pub code: i32,
    /// The final point.
    pub x: Vec<f64>,
    /// `f(x)`.
    pub objective: f64,
    /// Iterations (the last `iter_count` IPOPT reported, restoration included).
    pub iterations: usize,
}

/// The problem and the bookkeeping the callbacks share.
struct Session<'a> {
    nlp: &'a dyn Nlp,
    m_eq: usize,
    jac: Structure,
    hess: Structure,
    iterations: usize,
    outside_structure: bool,
}

/// # Safety (all callbacks)
/// IPOPT passes back the `user` pointer given to `IpoptSolve` (a live `Session`) and arrays of
/// the sizes the problem was created with.
fn session<'s>(user: *mut c_void) -> &'s mut Session<'s> {
    unsafe { &mut *(user as *mut Session) }
}

/// `len` numbers at `p`; empty for a null pointer (IPOPT passes null `x` and multipliers when
/// it asks for a structure).
fn slice<'s>(p: *mut f64, len: usize) -> &'s mut [f64] {
    if len == 0 || p.is_null() {
        return &mut [];
    }
    unsafe { std::slice::from_raw_parts_mut(p, len) }
}

extern "C" fn eval_f(n: Index, x: *mut f64, _new: Bool, obj: *mut f64, user: *mut c_void) -> Bool {
    let s = session(user);
    let x = slice(x, n as usize);
    let f = s.nlp.objective(x);
    unsafe { *obj = f };
    f.is_finite() as Bool
}

extern "C" fn eval_grad_f(n: Index, x: *mut f64, _new: Bool, grad: *mut f64, user: *mut c_void) -> Bool {
    let s = session(user);
    let x = slice(x, n as usize);
    let g = s.nlp.gradient(x);
    slice(grad, n as usize).copy_from_slice(&g);
    g.iter().all(|v| v.is_finite()) as Bool
}

extern "C" fn eval_g(n: Index, x: *mut f64, _new: Bool, m: Index, g: *mut f64, user: *mut c_void) -> Bool {
    let s = session(user);
    let out = slice(g, m as usize);
    out.copy_from_slice(&stacked_constraints(s.nlp, slice(x, n as usize)));
    out.iter().all(|v| v.is_finite()) as Bool
}

extern "C" fn eval_jac_g(
    n: Index,
    x: *mut f64,
    _new: Bool,
    _m: Index,
    nele: Index,
    rows: *mut Index,
    cols: *mut Index,
    values: *mut f64,
    user: *mut c_void,
) -> Bool {
    let s = session(user);
    let x = slice(x, n as usize);
    let (nlp, m_eq) = (s.nlp, s.m_eq);
    answer(&s.jac, nele, rows, cols, values, &mut s.outside_structure, || {
        stacked_jacobian(nlp, x, m_eq)
    })
}

extern "C" fn eval_h(
    n: Index,
    x: *mut f64,
    _new_x: Bool,
    obj_factor: f64,
    m: Index,
    lambda: *mut f64,
    _new_lambda: Bool,
    nele: Index,
    rows: *mut Index,
    cols: *mut Index,
    values: *mut f64,
    user: *mut c_void,
) -> Bool {
    let s = session(user);
    let x = slice(x, n as usize);
    let lambda = slice(lambda, m as usize);
    let (nlp, m_eq) = (s.nlp, s.m_eq);
    // Split only when the values are asked: a structure call may pass no multipliers.
    answer(
        &s.hess,
        nele,
        rows,
        cols,
        values,
        &mut s.outside_structure,
        || {
            let (eq, ineq) = lambda.split_at(m_eq);
            nlp.hessian(x, obj_factor, eq, ineq)
        },
    )
}

/// One of IPOPT's two-way calls for a sparse matrix with structure `st`: the positions when
/// `values` is null (`x` and the multipliers may then be null too, and are not read), else the
/// values of `triplets()`; an entry outside the structure sets `outside` and fails the call.
fn answer(
    st: &Structure,
    nele: Index,
    rows: *mut Index,
    cols: *mut Index,
    values: *mut f64,
    outside: &mut bool,
    triplets: impl FnOnce() -> Triplets,
) -> Bool {
    let len = (nele.max(0) as usize).min(st.len());
    if values.is_null() {
        unsafe {
            std::ptr::copy_nonoverlapping(st.rows_i32.as_ptr(), rows, len);
            std::ptr::copy_nonoverlapping(st.cols_i32.as_ptr(), cols, len);
        }
        return 1;
    }
    let ok = st.scatter(&triplets(), slice(values, len));
    *outside |= !ok;
    ok as Bool
}

extern "C" fn intermediate(
    _mode: Index,
    iter: Index,
    _obj: f64,
    _inf_pr: f64,
    _inf_du: f64,
    _mu: f64,
    _d_norm: f64,
    _reg: f64,
    _alpha_du: f64,
    _alpha_pr: f64,
    _ls: Index,
    user: *mut c_void,
) -> Bool {
    session(user).iterations = iter.max(0) as usize;
    1
}

fn cstr(s: &str) -> CString {
    CString::new(s).unwrap_or_default()
}

/// IPOPT 3.11 with MUMPS is not thread-safe: one solve at a time in this process.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Solves `nlp` from `x0` with IPOPT (exact Hessian, the options given); one solve at a time.
pub fn solve(nlp: &dyn Nlp, x0: &[f64], opt: &IpoptOptions) -> IpoptSolution {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (n, m_eq, m_in) = (nlp.num_vars(), nlp.num_eq(), nlp.num_ineq());
    let fail = |status| IpoptSolution {
        status,
        code: i32::MIN,
        x: x0.to_vec(),
        objective: f64::NAN,
        iterations: 0,
    };
    if x0.len() != n {
        return fail(Status::InvalidProblem);
    }
    let (mut xl, mut xu) = nlp.bounds();
    let (mut gl, mut gu) = stacked_bounds(nlp);
    // IPOPT reads ±1e19 and beyond as no bound.
    let big = 1e20;
    let clip = |v: &mut f64| *v = v.clamp(-big, big);
    xl.iter_mut().chain(xu.iter_mut()).for_each(clip);
    gl.iter_mut().chain(gu.iter_mut()).for_each(clip);
    let (jac, hess) = Structure::of(nlp, x0);
    let mut session = Session {
        nlp,
        m_eq,
        iterations: 0,
        outside_structure: false,
        jac,
        hess,
    };
    let mut x = x0.to_vec();
    let mut objective = f64::NAN;
    let code = unsafe {
        let p = CreateIpoptProblem(
            n as Index,
            xl.as_mut_ptr(),
            xu.as_mut_ptr(),
            (m_eq + m_in) as Index,
            gl.as_mut_ptr(),
            gu.as_mut_ptr(),
            session.jac.len() as Index,
            session.hess.len() as Index,
            0,
            eval_f,
            eval_g,
            eval_grad_f,
            eval_jac_g,
            eval_h,
        );
        if p.is_null() {
            return fail(Status::InvalidProblem);
        }
        AddIpoptNumOption(p, cstr("tol").as_ptr(), opt.tol);
        AddIpoptIntOption(
            p,
            cstr("max_iter").as_ptr(),
            opt.max_iter.min(i32::MAX as usize) as c_int,
        );
        AddIpoptNumOption(p, cstr("bound_relax_factor").as_ptr(), opt.bound_relax_factor);
        AddIpoptIntOption(p, cstr("print_level").as_ptr(), opt.print_level);
        AddIpoptStrOption(p, cstr("hessian_approximation").as_ptr(), cstr("exact").as_ptr());
        AddIpoptStrOption(p, cstr("sb").as_ptr(), cstr("yes").as_ptr());
        SetIntermediateCallback(p, intermediate);
        let code = IpoptSolve(
            p,
            x.as_mut_ptr(),
            std::ptr::null_mut(),
            &mut objective,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            &mut session as *mut Session as *mut c_void,
        );
        FreeIpoptProblem(p);
        code
    };
    let status = if session.outside_structure {
        Status::NumericalFailure
    } else {
        match code {
            0 => Status::Solved,
            1 => Status::SolvedToAcceptableLevel,
            2 => Status::LocallyInfeasible,
            -1 => Status::MaxIterations,
            -2 => Status::RestorationFailed,
            -11 | -12 => Status::InvalidProblem,
            _ => Status::NumericalFailure,
        }
    };
    IpoptSolution {
        status,
        code,
        x,
        objective,
        iterations: session.iterations,
    }
}
