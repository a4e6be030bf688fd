"""Where one of our peer runs spends its instructions: a callgrind profile of
`fmu-bench peer-run ... --samples 0` cut into the parts of a generalized-alpha step.

    valgrind --tool=callgrind --callgrind-out-file=OUT target/release/fmu-bench peer-run \\
        --case c2 --formulation "5 x 2 substructures" --setting "fixed step 1.0e-3 s" --samples 0
    python3 bench/peer/cost_shares.py OUT [OUT ...]

Instruction counts do not depend on the machine's load. Each part is the inclusive count of the
functions named below (release build, so what the compiler inlined is counted in its caller),
as a share of the unit's steps (`Engine::do_step`); the parts do not overlap:

  residual             Equations::body_residual (bodies' inertia, elastic and stiffening forces)
  constraints          constraints_and_rows and Gᵀλ (add_transpose_times)
  matrix assembly      IterationMatrix::factorize less the LU decomposition in it
  LU factorization     nalgebra's LU::new (dense) or faer's sparse LU numeric factorization
  back-substitution    Newton's solves with the factors (Stepper::solve_turned: the solve, dense
                       or sparse, and the turning of its right-hand side and solution)
  error estimate       Stepper::error_norm (the third difference, the filter's two solves)
  outputs              what do_step does beside Stepper::advance (interpolation to the
                       communication point, validity monitor)
  rest                 the remainder of Stepper::advance: predictor, vector updates, norms,
                       allocation

A profile of Exudyn (python running bench/peer/exudyn_cases.run under callgrind) is cut into
its SolveSystem's Newton residuals, Jacobian, factorization and solves.
"""
import re
import subprocess
import sys

PARTS = [
    ('residual', [r'Equations>::body_residual$']),
    ('constraints', [r'Equations>::constraints_and_rows$', r'JacobianRows::add_transpose_times$']),
    ('matrix assembly+LU', [r'IterationMatrix::factorize$']),
    ('LU factorization', [r'nalgebra::linalg::lu::LU<T,R,C>::new$',
                          r'faer::sparse::linalg::lu::SymbolicLu<I>::factorize_numeric_lu$']),
    ('back-substitution', [r'Stepper>::solve_turned$']),
    ('error estimate', [r'Stepper>::error_norm$', r'Stepper::error_norm$']),
    ('advance', [r'generalized_alpha::Stepper::advance$']),
    ('do_step', [r'Engine::do_step$']),
    ('malloc/free', [r'^malloc$', r'^free$', r'_int_free$', r'_int_malloc$', r'^realloc$']),
]


def inclusive(path):
    out = subprocess.run(['callgrind_annotate', '--inclusive=yes', '--threshold=100', path],
                         capture_output=True, text=True, check=True).stdout
    counts = {}
    for line in out.splitlines():
        m = re.match(r'\s*([\d,]+) \(\s*[\d.]+%\)\s+(\S.*?):(.*?)(?: \[.*\])?$', line)
        if not m:
            continue
        n = int(m.group(1).replace(',', ''))
        name = m.group(3).strip()
        counts[name] = max(counts.get(name, 0), n)
    return counts


def part(counts, patterns):
    total = 0
    for name, n in counts.items():
        if "'" in name:    # a recursive call's own entry: already inside the outer one
            continue
        if any(re.search(p, name) for p in patterns):
            total += n
    return total


def shares(path):
    c = inclusive(path) if isinstance(path, str) else path
    p = {name: part(c, pats) for name, pats in PARTS}
    step = p['do_step']
    res = {
        'residual': p['residual'],
        'constraints': p['constraints'],
        'matrix assembly': p['matrix assembly+LU'] - p['LU factorization'],
        'LU factorization': p['LU factorization'],
        'back-substitution': p['back-substitution'],
        'error estimate': p['error estimate'],
    }
    # the error estimate's filter solves with the factors: counted there, not twice
    res['rest'] = p['advance'] - sum(res.values())
    res['outputs'] = step - p['advance']
    return step, res, p['malloc/free']


EXUDYN = [
    ('solve', [r'^CSolverBase::SolveSystem\(']),
    ('residual', [r'^CSolverImplicitSecondOrderTimeInt::ComputeNewtonResidual\(']),
    ('jacobian', [r'^CSolverImplicitSecondOrderTimeInt::ComputeNewtonJacobian\(']),
    ('factorization', [r'^GeneralMatrix\w*::FactorizeNew\(', r'^GeneralMatrix\w*::Factorize\(']),
    ('back-substitution', [r'^GeneralMatrix\w*::Solve\(']),
    ('python', [r'^pybind11::detail::\w*::operator\(\)|^PyObject_Call$']),
]


def exudyn_shares(c):
    """Exudyn's SolveSystem (run under callgrind in a python process) cut the same way:
    Newton residuals (with the load and offset user functions, Python calls), the Jacobian,
    its factorization, the solves."""
    p = {name: part(c, pats) for name, pats in EXUDYN}
    solve = p['solve']
    res = {
        'residual': p['residual'],
        'jacobian (assembly)': p['jacobian'],
        'factorization': p['factorization'],
        'back-substitution': p['back-substitution'],
    }
    res['rest'] = solve - sum(res.values())
    return solve, res


def main():
    for path in sys.argv[1:]:
        c = inclusive(path)
        if any(k.startswith('CSolverBase::SolveSystem(') for k in c):
            solve, res = exudyn_shares(c)
            print('%s: %.1f M instructions in Exudyn\'s SolveSystem' % (path, solve / 1e6))
            for k, v in res.items():
                print('  %-20s %6.1f %%  (%.1f M)' % (k, 100.0 * v / solve, v / 1e6))
            continue
        step, res, alloc = shares(c)
        print('%s: %.1f M instructions in do_step' % (path, step / 1e6))
        for k, v in res.items():
            print('  %-18s %6.1f %%  (%.1f M)' % (k, 100.0 * v / step, v / 1e6))
        print('  (malloc/free, across the parts: %.1f %%)' % (100.0 * alloc / step))


if __name__ == '__main__':
    main()
