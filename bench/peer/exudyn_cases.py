"""Exudyn models of the benchmark cases C2, C3 and C4 (planar, 2D ANCF cable elements).

Written for this project from the case definitions in CASES.md; nothing here is copied
from Exudyn's examples.

    run(case, n_elements, step, spectral_radius=..., ...) -> Result

Every run integrates with Exudyn's implicit generalized-alpha solver (index-3 constraints,
modified Newton, fixed step) and returns the case's outputs sampled on the case's output
grid (C2, C3: every 1e-3 s; C4: every 1e-2 s; t = 0 included), together with the CPU time
of the solve alone (process time around mbs.SolveDynamic; model building excluded) and the
number of steps taken.

Modelling choices (the same for the references and the sweep):
  * beams: ObjectANCFCable2D (geometrically exact planar Euler-Bernoulli cable: axial strain
    |r'|-1, curvature from r' x r''; no rotary inertia of the cross section), straight
    reference configuration, generated with exudyn.beams.GenerateBeamElementsAlongLine;
  * pins: CoordinateConstraints on nodal position coordinates (to the ground, or between the
    end nodes of two beams, which share their reference position), slopes left free;
  * massless slider (C3): the rod's end node itself is held on the x axis by a
    CoordinateConstraint on its y coordinate: a prismatic joint without any slider mass, so no
    small stand-in mass is needed;
  * crank torque (C3): LoadTorqueVector on a MarkerBodyRigid at the crank root (the ANCF
    element's rotation is the direction of its slope vector); for the rigid crank,
    LoadTorqueVector on the ObjectRigidBody2D;
  * hub (C4): ObjectJointGeneric from the ground to a MarkerBodyRigid at the beam root,
    locking the rotation about z, with an offsetUserFunction giving theta(t); the root position
    is held at the origin by CoordinateConstraints;
  * Newton tolerances: Exudyn's default absolute tolerance (1e-10) is below round-off for
    these models (constraint residuals are scaled by 1/(beta h^2)), which makes Newton report
    failure, cut the step and, for C4, go unstable; we set relative and absolute tolerances
    explicitly, per case and step (see DEFAULT_NEWTON and default_absolute_tolerance).
  * Exudyn's explicit solvers (RK44, RK67, DOPRI5) can be selected for C2 (integrator=...),
    but they are NOT used for the references or the sweep: with eliminateConstraints they give
    wrong dynamics for the pinned ANCF pendulum (see bench/peer/README.md).
"""
import math
import time

import numpy as np
import exudyn as exu
import exudyn.beams as eb
from exudyn.itemInterface import (ObjectANCFCable2D, ObjectGround, ObjectRigidBody2D,
                                  NodePointGround, NodeRigidBody2D, MarkerNodeCoordinate,
                                  MarkerBodyRigid, MarkerBodyPosition, MarkerNodePosition,
                                  CoordinateConstraint, ObjectJointGeneric,
                                  ObjectJointRevolute2D, LoadTorqueVector, SensorNode, SensorBody)

G = 9.81

CASES = {
    'c2': dict(end=1.0, dt_out=1e-3, outputs=('chord_angle', 'tip_deflection', 'tip_x', 'tip_y')),
    'c3_elastic': dict(end=1.6, dt_out=1e-3, outputs=('slider_position', 'rod_mid_deflection')),
    'c3_rigid': dict(end=1.6, dt_out=1e-3, outputs=('slider_position', 'rod_mid_deflection')),
    'c4_omega10': dict(end=20.0, dt_out=1e-2, outputs=('tip_deflection',), omega=10.0),
    'c4_omega4': dict(end=20.0, dt_out=1e-2, outputs=('tip_deflection',), omega=4.0),
}

# C2 flexible pendulum
C2 = dict(L=0.4, A=0.0018, rho=5540.0, J=1.215e-8, E=1e9)
# C3 slider-crank
C3_CRANK = dict(L=0.152, A=0.7854e-4, J=4.909e-10, rho=2770.0, E=1e9)
C3_ROD = dict(L=0.304, A=0.7854e-4, J=4.909e-10, rho=2770.0, E=5e7)
C3_T_OFF = 0.7
# C4 spin-up
C4 = dict(L=8.0, A=7.299e-5, J=8.214e-9, rho=2767.0, E=6.895e10)
C4_T = 15.0

# Newton settings used unless overridden: relative tolerance on the residual (Exudyn's default)
# and an absolute tolerance (residual in N) above round-off. The round-off floor of the scaled
# constraint rows grows like 1/h^2, so below h = 1e-5 s the absolute tolerance grows with it.
DEFAULT_NEWTON = dict(relative_tolerance=1e-8, absolute_tolerance=1e-6)


def default_absolute_tolerance(step, case='c2'):
    """Absolute Newton tolerance (residual in N). C3's forces are about 1e-2 of C2's and C4's
    (torque 0.01 N m on links of 0.03 kg), so its tolerance is scaled down: with the C2 rule,
    at h = 5e-6 s the initial residual of a C3 step can be below the tolerance, Newton then does
    not iterate and the solution drifts by percents (seen in the first C3 reference runs)."""
    if case.startswith('c3'):
        return 1e-8 * max(1.0, (2e-5 / step) ** 2)
    return DEFAULT_NEWTON['absolute_tolerance'] * max(1.0, (1e-5 / step) ** 2)


def c3_torque(t, off=False):
    """Drive torque of C3 in N m: 0.01 (1 - exp(-t/0.167)) up to 0.7 s, 0 after. The steps
    land on 0.7 s; the tolerance keeps a step end at 0.7 s plus round-off on the loaded side.
    `off`: the run's second phase, which starts at 0.7 s with the torque cut (see `run`)."""
    if off:
        return 0.0
    return 0.01 * (1.0 - math.exp(-t / 0.167)) if t <= C3_T_OFF + 1e-9 else 0.0


def c4_theta(t, omega):
    """Prescribed hub angle of C4 (rad)."""
    T = C4_T
    if t < T:
        return omega / T * (t * t / 2.0 + (T / (2.0 * math.pi)) ** 2
                            * (math.cos(2.0 * math.pi * t / T) - 1.0))
    return omega * (t - T / 2.0)


def _cable(p):
    return ObjectANCFCable2D(massPerLength=p['rho'] * p['A'], bendingStiffness=p['E'] * p['J'],
                             axialStiffness=p['E'] * p['A'])


class Result:
    def __init__(self, t, outputs, cpu, steps, info):
        self.t = t                  # output grid (s)
        self.outputs = outputs      # dict name -> array on the grid
        self.cpu = cpu              # CPU seconds of mbs.SolveDynamic
        self.steps = steps          # steps taken
        self.info = info            # dict: newton iterations, jacobians, success, ...


def _pin_to_ground(mbs, node, coords=(0, 1)):
    ng = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ng, coordinate=0))
    for c in coords:
        m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=c))
        mbs.AddObject(CoordinateConstraint(markerNumbers=[mg, m]))


def _pin_nodes(mbs, node_a, node_b):
    """Revolute joint between two ANCF nodes with the same reference position: equal x and y
    displacement coordinates, slopes free."""
    for c in (0, 1):
        ma = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node_a, coordinate=c))
        mb = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node_b, coordinate=c))
        mbs.AddObject(CoordinateConstraint(markerNumbers=[ma, mb]))


def _sensor_node(mbs, node, ovt):
    return mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=ovt,
                                    storeInternal=True, writeToFile=False))


def _sensor_body(mbs, body, local, ovt):
    return mbs.AddSensor(SensorBody(bodyNumber=body, localPosition=local, outputVariableType=ovt,
                                    storeInternal=True, writeToFile=False))


def _build_c2(mbs, ne):
    p = C2
    d = eb.GenerateBeamElementsAlongLine(mbs, [0, 0, 0], [p['L'], 0, 0], ne, _cable(p),
                                         gravity=[0, -G, 0])
    nodes = d['nodes']
    _pin_to_ground(mbs, nodes[0])
    s_root = _sensor_node(mbs, nodes[0], exu.OutputVariableType.Coordinates)
    s_tip = _sensor_node(mbs, nodes[-1], exu.OutputVariableType.Position)

    def outputs(get):
        q0 = get(s_root)          # displacement coordinates of the root node: ux, uy, dslope_x, dslope_y
        tip = get(s_tip)
        root = q0[:, 0:2]          # the root's reference position is the origin
        tx = 1.0 + q0[:, 2]
        ty = q0[:, 3]
        nt = np.hypot(tx, ty)
        tx, ty = tx / nt, ty / nt
        dx = tip[:, 0] - root[:, 0]
        dy = tip[:, 1] - root[:, 1]
        # continuous (unwrapped) angle: the pendulum swings through -pi, where atan2 jumps
        return {'chord_angle': np.unwrap(np.arctan2(dy, dx)),
                'tip_deflection': -ty * dx + tx * dy,
                # the tip's position in the world (the root is pinned at the origin)
                'tip_x': tip[:, 0], 'tip_y': tip[:, 1]}
    return outputs


def _build_c3(mbs, ne, rigid_crank, ne_crank=None, torque_off=None):
    pc, pr = C3_CRANK, C3_ROD
    Lc = pc['L']
    if ne_crank is None:
        ne_crank = max(1, ne // 2)        # the crank is half the rod's length: same element size
    rod = eb.GenerateBeamElementsAlongLine(mbs, [Lc, 0, 0], [Lc + pr['L'], 0, 0], ne, _cable(pr))
    rnodes, relems = rod['nodes'], rod['elements']
    ground = mbs.AddObject(ObjectGround())
    if rigid_crank:
        m = pc['rho'] * pc['A'] * Lc
        nc = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[Lc / 2, 0, 0]))
        crank = mbs.AddObject(ObjectRigidBody2D(nodeNumber=nc, mass=m, inertia=m * Lc ** 2 / 12.0))
        mg = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0]))
        mc0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=crank, localPosition=[-Lc / 2, 0, 0]))
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[mg, mc0]))
        mc1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=crank, localPosition=[Lc / 2, 0, 0]))
        mr0 = mbs.AddMarker(MarkerNodePosition(nodeNumber=rnodes[0]))
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[mc1, mr0]))
        mtorque = mbs.AddMarker(MarkerBodyRigid(bodyNumber=crank, localPosition=[0, 0, 0]))
    else:
        cr = eb.GenerateBeamElementsAlongLine(mbs, [0, 0, 0], [Lc, 0, 0], ne_crank, _cable(pc))
        cnodes = cr['nodes']
        _pin_to_ground(mbs, cnodes[0])
        _pin_nodes(mbs, cnodes[-1], rnodes[0])
        mtorque = mbs.AddMarker(MarkerBodyRigid(bodyNumber=cr['elements'][0], localPosition=[0, 0, 0]))
    # massless slider: the rod end stays on the x axis
    _pin_to_ground(mbs, rnodes[-1], coords=(1,))
    mbs.AddLoad(LoadTorqueVector(markerNumber=mtorque, loadVector=[0, 0, 0],
                                 loadVectorUserFunction=lambda mbs, t, lv: [
                                     0.0, 0.0, c3_torque(t, torque_off is not None and torque_off[0])]))
    # rod mid-span point: inside element k at local coordinate xm
    le = pr['L'] / ne
    k = min(ne // 2, ne - 1)
    xm = pr['L'] / 2 - k * le
    s_a = _sensor_node(mbs, rnodes[0], exu.OutputVariableType.Position)
    s_b = _sensor_node(mbs, rnodes[-1], exu.OutputVariableType.Position)
    s_m = _sensor_body(mbs, relems[k], [xm, 0, 0], exu.OutputVariableType.Position)

    def outputs(get):
        a, b, mid = get(s_a), get(s_b), get(s_m)
        cx, cy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
        cn = np.hypot(cx, cy)
        cx, cy = cx / cn, cy / cn
        return {'slider_position': b[:, 0],
                'rod_mid_deflection': -cy * (mid[:, 0] - a[:, 0]) + cx * (mid[:, 1] - a[:, 1])}
    return outputs


def _build_c4(mbs, ne, omega):
    p = C4
    d = eb.GenerateBeamElementsAlongLine(mbs, [0, 0, 0], [p['L'], 0, 0], ne, _cable(p))
    nodes, elems = d['nodes'], d['elements']
    _pin_to_ground(mbs, nodes[0])
    ground = mbs.AddObject(ObjectGround())
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    mr = mbs.AddMarker(MarkerBodyRigid(bodyNumber=elems[0], localPosition=[0, 0, 0]))
    mbs.AddObject(ObjectJointGeneric(
        markerNumbers=[mg, mr], constrainedAxes=[0, 0, 0, 0, 0, 1],
        offsetUserFunction=lambda mbs, t, itemNumber, par: [0, 0, 0, 0, 0, c4_theta(t, omega)]))
    s_tip = _sensor_node(mbs, nodes[-1], exu.OutputVariableType.Position)

    def outputs(get, t):
        tip = get(s_tip)
        th = np.array([c4_theta(ti, omega) for ti in t])
        return {'tip_deflection': -np.sin(th) * tip[:, 0] + np.cos(th) * tip[:, 1]}
    return outputs


def build(case, ne, ne_crank=None, torque_off=None):
    """Builds the case in a fresh system; returns (SC, mbs, outputs-function). `torque_off`: a
    one-element list whose True cuts C3's torque (the second phase of `run`)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    if case == 'c2':
        f = _build_c2(mbs, ne)
        out = lambda get, t: f(get)
    elif case in ('c3_elastic', 'c3_rigid'):
        f = _build_c3(mbs, ne, rigid_crank=(case == 'c3_rigid'), ne_crank=ne_crank,
                      torque_off=torque_off)
        out = lambda get, t: f(get)
    elif case.startswith('c4'):
        out = _build_c4(mbs, ne, CASES[case]['omega'])
    else:
        raise ValueError(case)
    mbs.Assemble()
    return SC, mbs, out


def run(case, ne, step, spectral_radius=0.9, relative_tolerance=None, absolute_tolerance=None,
        modified_newton=True, newmark=False, ne_crank=None, adaptive_step=True, verbose=0,
        integrator='genalpha', error_tolerance=None, restart_at_jump=True):
    """One Exudyn run of `case` with `ne` elements per beam (the C3 crank gets ne//2 unless
    ne_crank is given) and fixed step `step` (must divide the output spacing).

    integrator: 'genalpha' (implicit, index 3; with newmark=True the trapezoidal rule with
    index-2 constraints), or one of Exudyn's explicit Runge-Kutta solvers 'RK44', 'RK67'
    (fixed step) and 'DOPRI5' (error-controlled: error_tolerance is its relative tolerance,
    the absolute one is 1e-2 times that, and `step` is the largest step). The explicit solvers
    work for C2 only: its pin is a set of ground CoordinateConstraints, which they eliminate.
    Returns a Result; outputs are None if the solver failed."""
    spec = CASES[case]
    end, dt_out = spec['end'], spec['dt_out']
    n_steps = int(round(end / step))
    if step > dt_out * (1 + 1e-9):
        # a step coarser than the case's grid: the outputs at the step points, a subset of
        # the grid (Exudyn writes sensors at step points; scored there, not interpolated)
        per_step = step / dt_out
        if abs(per_step - round(per_step)) > 1e-9:
            raise ValueError('a step above the output spacing must be a multiple of it')
        dt_out = step
    per_out = dt_out / step
    if abs(n_steps * step - end) > 1e-9 * end or abs(per_out - round(per_out)) > 1e-9:
        raise ValueError('step must divide the output spacing and the end time')
    per_out = int(round(per_out))
    rtol = DEFAULT_NEWTON['relative_tolerance'] if relative_tolerance is None else relative_tolerance
    atol = default_absolute_tolerance(step, case) if absolute_tolerance is None else absolute_tolerance

    # C3's torque jumps to 0 at 0.7 s. Generalized-alpha carries its acceleration variable
    # across a step, so a jump landed on but not restarted at drops the scheme to first order
    # (CASES.md; measured: crank 2, rod 4 at 1e-3 s, slider error 1.3e-6 before 0.7 s, 8.6e-4
    # after). As an Exudyn user would, the run stops at 0.7 s and starts again from that state
    # with the torque cut, where SolveSystem computes consistent initial accelerations (our
    # engine restarts there too). Both phases count in its CPU time, steps and iterations.
    torque_off = [False]
    phases = [(0.0, end)]
    if case.startswith('c3') and integrator == 'genalpha' and restart_at_jump:
        phases = [(0.0, C3_T_OFF), (C3_T_OFF, end)]
    SC, mbs, out = build(case, ne, ne_crank, torque_off)
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = end
    ti.numberOfSteps = n_steps
    if abs(phases[0][1] / step - round(phases[0][1] / step)) > 1e-9 * phases[0][1] / step:
        raise ValueError('step must divide the time of the torque cut-off')
    ti.verboseMode = verbose
    ti.adaptiveStep = adaptive_step
    ti.newton.relativeTolerance = rtol
    ti.newton.absoluteTolerance = atol
    ti.newton.useModifiedNewton = modified_newton
    ti.generalizedAlpha.spectralRadius = spectral_radius
    if newmark:   # trapezoidal rule with index-2 constraints (Exudyn's TrapezoidalIndex2 settings)
        ti.generalizedAlpha.useNewmark = True
        ti.generalizedAlpha.useIndex2Constraints = True
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = dt_out   # rows at the grid times (checked below)
    ss.show.computationTime = False
    ss.linearSolver.solverType = (exu.LinearSolverType.EigenSparse if mbs.systemData.ODE2Size() > 150
                                  else exu.LinearSolverType.EXUdense)

    explicit = integrator != 'genalpha'
    if explicit:
        if case != 'c2':
            raise ValueError('explicit solvers: C2 only (constraints between bodies are not eliminated)')
        ti.solverType = getattr(exu.DynamicSolverType, integrator)
        ti.explicit.eliminateConstraints = True
        ti.explicit.computeEndOfStepAccelerations = False
        ss.solution.sensors.writePeriod = dt_out
        if integrator == 'DOPRI5':
            ti.automaticStepSize = True
            ti.relativeTolerance = error_tolerance
            ti.absoluteTolerance = 1e-2 * error_tolerance
            ti.initialStepSize = 1e-7
        solver = exu.MainSolverExplicit()
    else:
        solver = exu.MainSolverImplicitSecondOrder()
    cpu, steps, newton, jacobians, rejected, ok, err = 0.0, 0, 0, 0, 0, True, ''
    stored = {}      # sensor -> rows of the phases before the last
    for k, (start, stop) in enumerate(phases):
        if k:
            # the next phase starts from this one's end state, the torque cut
            sd = mbs.systemData
            sd.SetODE2Coordinates(coordinates=sd.GetODE2Coordinates(),
                                  configuration=exu.ConfigurationType.Initial)
            sd.SetODE2Coordinates_t(coordinates=sd.GetODE2Coordinates_t(),
                                    configuration=exu.ConfigurationType.Initial)
            for sensor in range(mbs.systemData.NumberOfSensors()):
                stored.setdefault(sensor, []).append(mbs.GetSensorStoredData(sensor))
            torque_off[0] = True
        ti.startTime = start
        ti.endTime = stop
        ti.numberOfSteps = int(round((stop - start) / step))
        t0 = time.process_time()
        try:
            ok = solver.SolveSystem(mbs, ss)
        except Exception as e:   # Exudyn raises on solver failure
            ok = False
            err = str(e)
        cpu += time.process_time() - t0
        it = solver.it
        steps += it.currentStepIndex
        if not explicit:
            newton += it.newtonStepsCount
            jacobians += it.newtonJacobiCount
        else:
            rejected += it.rejectedAutomaticStepSizeSteps
        if not ok:
            break
    info = dict(success=bool(ok), error=err, ode2_size=mbs.systemData.ODE2Size(),
                phases=len(phases))
    if not explicit:
        info.update(newton_iterations=newton, jacobians=jacobians)
    else:
        info.update(rejected_steps=rejected)
    if not ok:
        return Result(None, None, cpu, steps, info)

    n_out = int(round(end / dt_out)) + 1
    t_grid = np.arange(n_out) * dt_out

    def get(sensor):
        data = mbs.GetSensorStoredData(sensor)
        if stored.get(int(sensor)):
            # the earlier phases' rows, each but its last (the next phase's first row)
            data = np.vstack([d[d[:, 0] < data[0, 0] - 0.25 * step] for d in stored[int(sensor)]]
                             + [data])
        tt = data[:, 0]
        # pick the rows at the grid times (with adaptive step cuts the rows are not regular)
        idx = np.searchsorted(tt, t_grid - 0.25 * min(step, dt_out))
        idx = np.minimum(idx, len(tt) - 1)
        if len(tt) != len(t_grid) or np.max(np.abs(tt[idx] - t_grid)) > 1e-6 * min(step, dt_out):
            # the rows are off the grid (e.g. after an adaptive step cut): interpolate linearly
            # and say so in info
            info['interpolated'] = True
            return np.column_stack([np.interp(t_grid, tt, data[:, j]) for j in range(1, data.shape[1])])
        return data[idx, 1:]

    outs = out(get, t_grid)
    return Result(t_grid, {k: np.asarray(outs[k]) for k in spec['outputs']}, cpu, steps, info)


if __name__ == '__main__':
    import sys
    case = sys.argv[1] if len(sys.argv) > 1 else 'c2'
    ne = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    h = float(sys.argv[3]) if len(sys.argv) > 3 else CASES[case]['dt_out']
    r = run(case, ne, h)
    print(case, ne, h, 'cpu %.3f s' % r.cpu, 'steps', r.steps, r.info)
    if r.outputs:
        for k, v in r.outputs.items():
            i = int(np.argmax(np.abs(v)))
            print('  %s: max |y| = %.6g at t = %.3f; final %.6g' % (k, abs(v[i]), r.t[i], v[-1]))
