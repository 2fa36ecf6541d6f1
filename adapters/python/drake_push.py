#!/usr/bin/env python3
"""A pushval outside engine in Drake (drake==1.51.1): MultibodyPlant, discrete.

One row per plant step, with the columns load_1..load_n (each foot's normal
force in the step, N, the problem's support order) and rise (the plate's
centre of mass above its height at the end of the settling, m); the protocol (one-shot or --session, limits,
progress, --timing) is pushval.adapter's (adapters/python/README.md).
Drake's contact makes the pusher's velocity jumps itself: impulsive
switching only.

The scene
---------
* The plant: discrete, time step = the segment's step h (the problem's dt, or
  duration / step count; a segment whose h differs rebuilds the plant and
  carries the state over), point contact only (hydroelastic off), the
  discrete contact approximation chosen by ``--approximation`` (tamsi,
  lagged, sap, similar).
* The plate: one rigid body, mass m, inertia I_cm about z and I_cm / 2 about
  x and y (a thin plate), its centre of mass at the height of the feet's
  lowest points, so that the pusher, the friction and the centre of mass act
  in one horizontal plane (no tipping moment, as in the 2-D model). Roll and
  pitch are free, as is the yaw.
* The feet: a sphere of radius 5 mm under each support, against a ground
  half-space. Stiffness and dissipation are set explicitly as proximity
  properties (Drake's default stiffness depends on every body's mass through
  the penetration allowance): each foot's stiffness is k_i = N_i / δ, N_i
  the problem's load on that support and δ the rest penetration
  (``point_stiffness`` scales them; default δ = 1e-4 m), so the plate rests
  level and each foot carries the problem's load when the loads balance the
  weight's moment. Drake combines two stiffnesses in series and places the
  contact point by their ratio (an infinite one gives NaN there), so the
  ground is 1e4 times the stiffest foot and each foot's own stiffness is
  raised to k_i k_g / (k_g − k_i): the pair's stiffness is k_i exactly. Hunt–Crossley dissipation d (s/m, TAMSI, Lagged,
  Similar) and the relaxation time τ_d (s, SAP; the pair's is the sum of the
  two geometries', the ground's is 0) default to critical damping of the
  plate's bounce on its feet: ω_n = sqrt(Σk_i / m), d = 2 ω_n / g,
  τ_d = 2 / ω_n.
* Friction: static = dynamic = the support's μ at the contact. Drake combines
  two geometries' coefficients as 2 μ_a μ_b / (μ_a + μ_b); the ground has
  μ_g = max μ_i and each foot μ_f = μ_i μ_g / (2 μ_g − μ_i), so the pair's
  coefficient is μ_i exactly. The stiction tolerance v_s (TAMSI, Lagged,
  Similar) is Drake's 1e-3 m/s unless set.
* The pusher: a chain world → carriage x (prismatic x) → carriage y
  (prismatic y) → tip (prismatic z) → plate (ball joint, roll-pitch-yaw, at
  the plate's contact point). The two carriage bodies weigh 1e6 m each (1e3 m
  under Lagged: see CARRIAGE_MASS_RATIOS) and
  their velocities are set before every step to the pusher's velocity at the
  step's middle (yaw extrapolated by ω h / 2), so they move as prescribed to
  1e-6 of the plate's reaction; the tip weighs 1e-3 m and the pusher's model
  instance has gravity off, so the vertical slide carries none of the
  plate's weight: the pusher fixes only the contact point's horizontal
  position. Why joints and not a constraint: TAMSI has no constraints (SAP's
  ball and weld constraints exist only for the convex approximations), and
  one scene for all four approximations makes their rows comparable; a
  stiff PD on actuated joints would be explicit under TAMSI and limit its
  step. This is the MuJoCo adapter's carriage (mujoco_push.py) in joints.
* Settling: before the first push the plate rests 0.2 s with the pusher
  still; its height then is the rest height the rise is measured from.
* The release (protocol 3's release; the step receives no push): a plant
  cannot lose a joint once finalized, so the plate is rebuilt alone, a free
  body, with its pose and spatial velocity carried over (a plate thrown
  without pushes gets its initial velocity and omega there), and slides on
  its feet to rest under the approximation's friction. TAMSI, Lagged and
  Similar regularise Coulomb's law below the stiction tolerance v_s
  (friction mu N u / v_s there) and solve it implicitly in the velocities,
  so near the stop the slip decays (time constant about v_s / (mu g),
  0.2 ms at the defaults) instead of reversing: no chattering; SAP's convex
  friction is implicit too.

Options (command line; a scenario's [engine] table overrides them with the
same names: stiction_tolerance, relaxation_time, hunt_crossley_dissipation,
penetration, near_rigid_threshold; other keys of the table are ignored):
  --approximation tamsi|lagged|sap|similar   (default tamsi)
  --stiction-tolerance V   m/s (default 1e-3, Drake's)
  --relaxation-time T      s, SAP's dissipation time scale (default critical)
  --dissipation D          s/m, Hunt–Crossley (default critical)
  --penetration P          m, rest penetration defining the stiffness (1e-4)
  --near-rigid-threshold B SAP's β (Drake's default 1.0)
  --check                  print the rest loads against the problem's on stderr
  --diag FILE              per-step diagnostics (CSV; appended per problem)
"""

import math
import os
import sys

try:
    from pushval.adapter import AdapterError, Engine, State, main
except ImportError:  # run from the source tree without the wheel installed
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
    from pushval.adapter import AdapterError, Engine, State, main

FOOT_RADIUS = 0.005
CARRIAGE_MASS_RATIO = 1e6
# Lagged's carriages weigh 1e3 m: the SAP solver stops when the scaled
# momentum residual ‖A^-1/2 ∇ℓ‖ is below rel_tolerance times
# max(‖A^-1/2 p‖, ‖A^-1/2 j‖) (sap_solver.cc), and the carriages' term
# sqrt(m_c) |v| dominates that scale. With 1e6 m, Lagged's residual at the
# initial guess (the plate's friction impulse alone: its normal impulse
# already balances the weight there) passed the test: the solver returned the
# guess, the plate moved without friction (omega 88 % below Coulomb at
# dt = 1e-3 s, 0 at 5e-4 s), while the contact results, evaluated at that
# velocity, still read mu N along -slip. With 1e3 m it iterates and matches
# TAMSI (results/friction_models/drake/README.md).
CARRIAGE_MASS_RATIOS = {"tamsi": CARRIAGE_MASS_RATIO, "lagged": 1e3,
                        "sap": CARRIAGE_MASS_RATIO, "similar": CARRIAGE_MASS_RATIO}
TIP_MASS_RATIO = 1e-3
SETTLE_TIME = 0.2
GROUND_STIFFNESS_RATIO = 1e4
DEFAULT_PENETRATION = 1e-4
DEFAULT_STICTION = 1e-3
APPROXIMATIONS = ("tamsi", "lagged", "sap", "similar")
OPTION_KEYS = {
    "stiction_tolerance": "stiction_tolerance",
    "relaxation_time": "relaxation_time",
    "hunt_crossley_dissipation": "dissipation",
    "penetration": "penetration",
    "near_rigid_threshold": "near_rigid_threshold",
}
DIAG_HEADER = (
    "problem,approximation,dt,t,foot,normal_n,load_problem_n,in_contact,slip_speed,"
    "friction_ratio,direction_error_rad,rise_m,sum_normal_n,weight_n"
)


class Settings:
    """The contact settings of one run (command line, then [engine])."""

    def __init__(self, args, problem):
        self.approximation = args.approximation
        vals = {
            "stiction_tolerance": args.stiction_tolerance,
            "relaxation_time": args.relaxation_time,
            "dissipation": args.dissipation,
            "penetration": args.penetration,
            "near_rigid_threshold": args.near_rigid_threshold,
        }
        for key, attr in OPTION_KEYS.items():
            if key in problem.options:
                v = problem.options[key]
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                    raise AdapterError(f"[engine] {key} must be a finite number >= 0, got {v!r}")
                vals[attr] = float(v)
        if vals["penetration"] is not None and not vals["penetration"] > 0:
            raise AdapterError("penetration must be > 0")
        self.stiction_tolerance = vals["stiction_tolerance"]
        self.penetration = vals["penetration"]
        self.near_rigid_threshold = vals["near_rigid_threshold"]
        loads = [s.normal_force for s in problem.supports]
        self.stiffness = [n / self.penetration for n in loads]
        wn = math.sqrt(sum(self.stiffness) / problem.mass)
        self.omega_n = wn
        self.dissipation = vals["dissipation"] if vals["dissipation"] is not None else 2.0 * wn / problem.gravity
        self.relaxation_time = vals["relaxation_time"] if vals["relaxation_time"] is not None else 2.0 / wn

    def describe(self):
        return (
            f"{self.approximation}: stiction_tolerance={self.stiction_tolerance!r} m/s, "
            f"hunt_crossley_dissipation={self.dissipation!r} s/m, relaxation_time={self.relaxation_time!r} s, "
            f"penetration={self.penetration!r} m (k_i = N_i / penetration), "
            f"near_rigid_threshold={self.near_rigid_threshold!r}"
        )


class DrakePush(Engine):
    """The plate on point feet in Drake's MultibodyPlant (discrete)."""

    name = "drake_push.py"
    can_release = True

    @classmethod
    def add_arguments(cls, parser):
        parser.add_argument("--approximation", choices=APPROXIMATIONS, default="tamsi",
                            help="Drake's discrete contact approximation")
        parser.add_argument("--stiction-tolerance", type=float, default=DEFAULT_STICTION,
                            help="m/s (TAMSI, Lagged, Similar; Drake's default 1e-3)")
        parser.add_argument("--relaxation-time", type=float, default=None,
                            help="s, SAP's dissipation time scale (default: critical damping)")
        parser.add_argument("--dissipation", type=float, default=None,
                            help="s/m, Hunt-Crossley (TAMSI, Lagged, Similar; default: critical damping)")
        parser.add_argument("--penetration", type=float, default=DEFAULT_PENETRATION,
                            help="m, rest penetration: each foot's stiffness is its load / this")
        parser.add_argument("--near-rigid-threshold", type=float, default=1.0,
                            help="SAP's near-rigid threshold beta (Drake's default 1.0)")
        parser.add_argument("--check", action="store_true",
                            help="print the rest loads against the problem's on standard error")
        parser.add_argument("--diag", metavar="FILE", default=None,
                            help="append per-step diagnostics to FILE (CSV)")

    def __init__(self, args=None):
        super().__init__(args)
        try:
            import numpy
            import pydrake
            from pydrake import geometry, math as dmath, multibody
            from pydrake.multibody import plant as mbp, tree
            from pydrake.systems import framework
            from pydrake.systems.analysis import Simulator
        except ImportError as e:
            raise AdapterError(f"{e}; install it with scripts/setup-adapters.sh") from None
        self.np = numpy
        self.Simulator = Simulator
        self.geometry, self.dmath, self.mbp, self.tree, self.framework = geometry, dmath, mbp, tree, framework
        try:
            from importlib.metadata import version

            self.version = version("drake")
        except Exception:  # noqa: BLE001 - the version is for the record only
            self.version = "?"
        self.problems = 0
        self.diag = None
        if self.args.diag:
            new = not os.path.exists(self.args.diag) or os.path.getsize(self.args.diag) == 0
            self.diag = open(self.args.diag, "a", encoding="utf-8")
            if new:
                self.diag.write(DIAG_HEADER + "\n")
        print(f"drake_push.py: drake {self.version}, {self.args.approximation}", file=sys.stderr)

    # ------------------------------------------------------------------
    # The scene

    def build(self, h, released=False):
        """Builds the diagram with time step h (s); returns nothing, sets
        self.diagram, self.plant, self.context, self.plant_context.
        ``released``: the plate alone, a free body (no pusher chain)."""
        p, s = self.problem, self.settings
        G, M, MBP, T = self.geometry, self.dmath, self.mbp, self.tree
        np = self.np
        builder = self.framework.DiagramBuilder()
        plant, _sg = MBP.AddMultibodyPlantSceneGraph(builder, time_step=h)
        approx = {
            "tamsi": MBP.DiscreteContactApproximation.kTamsi,
            "lagged": MBP.DiscreteContactApproximation.kLagged,
            "sap": MBP.DiscreteContactApproximation.kSap,
            "similar": MBP.DiscreteContactApproximation.kSimilar,
        }[s.approximation]
        plant.set_discrete_contact_approximation(approx)
        plant.set_contact_model(MBP.ContactModel.kPoint)
        plant.set_stiction_tolerance(s.stiction_tolerance)
        if s.approximation != "tamsi":
            plant.set_sap_near_rigid_threshold(s.near_rigid_threshold)
        m, i_z = p.mass, p.inertia_cm
        pusher = plant.AddModelInstance("pusher")
        obj = plant.AddModelInstance("object")
        mc, mt = CARRIAGE_MASS_RATIOS[s.approximation] * m, TIP_MASS_RATIO * m

        def inertia(mass, ixx, iyy, izz):
            return T.SpatialInertia.MakeFromCentralInertia(mass, np.zeros(3), T.RotationalInertia(ixx, iyy, izz))

        plate = plant.AddRigidBody("plate", obj, inertia(m, 0.5 * i_z, 0.5 * i_z, i_z))
        joints = None
        if not released:
            bx = plant.AddRigidBody("carriage_x", pusher, inertia(mc, mc, mc, mc))
            by = plant.AddRigidBody("carriage_y", pusher, inertia(mc, mc, mc, mc))
            tip = plant.AddRigidBody("tip", pusher, inertia(mt, mt * 1e-4, mt * 1e-4, mt * 1e-4))
            jx = plant.AddJoint(T.PrismaticJoint("x", plant.world_frame(), bx.body_frame(), [1.0, 0.0, 0.0]))
            jy = plant.AddJoint(T.PrismaticJoint("y", bx.body_frame(), by.body_frame(), [0.0, 1.0, 0.0]))
            jz = plant.AddJoint(T.PrismaticJoint("z", by.body_frame(), tip.body_frame(), [0.0, 0.0, 1.0]))
            rc = p.contact_offset
            contact_frame = plant.AddFrame(
                T.FixedOffsetFrame("contact", plate.body_frame(), M.RigidTransform([rc[0], rc[1], 0.0])))
            ball = plant.AddJoint(T.BallRpyJoint("ball", tip.body_frame(), contact_frame))
            joints = (jx, jy, jz, ball)
            plant.gravity_field().set_enabled(pusher, False)
        plant.gravity_field().set_gravity_vector([0.0, 0.0, -p.gravity])

        # Contact: ground rigid, feet compliant; μ combined to the support's.
        mus = [sup.mu for sup in p.supports]
        mu_g = max(mus) if max(mus) > 0 else 1.0
        # Drake combines stiffnesses in series, k = k_a k_b / (k_a + k_b), and
        # places the contact point by k_a / (k_a + k_b): an infinite ground
        # stiffness gives NaN there, so the ground is 1e4 times the stiffest
        # foot and each foot's own stiffness is raised to make the pair's k_i.
        k_g = GROUND_STIFFNESS_RATIO * max(s.stiffness)
        ground = G.ProximityProperties()
        G.AddContactMaterial(dissipation=s.dissipation, point_stiffness=k_g,
                             friction=MBP.CoulombFriction(mu_g, mu_g), properties=ground)
        ground.AddProperty("material", "relaxation_time", 0.0)
        plant.RegisterCollisionGeometry(plant.world_body(), M.RigidTransform(), G.HalfSpace(), "ground", ground)
        r = FOOT_RADIUS
        self.foot_ids = []
        for k, sup in enumerate(p.supports):
            mu_f = sup.mu * mu_g / (2.0 * mu_g - sup.mu) if sup.mu > 0 else 0.0
            props = G.ProximityProperties()
            k_f = s.stiffness[k] * k_g / (k_g - s.stiffness[k])
            G.AddContactMaterial(dissipation=s.dissipation, point_stiffness=k_f,
                                 friction=MBP.CoulombFriction(mu_f, mu_f), properties=props)
            props.AddProperty("material", "relaxation_time", s.relaxation_time)
            sx, sy = sup.offset
            gid = plant.RegisterCollisionGeometry(plate, M.RigidTransform([sx, sy, r]), G.Sphere(r), f"foot{k}", props)
            self.foot_ids.append(gid)
        plant.Finalize()
        diagram = builder.Build()
        self.diagram, self.plant = diagram, plant
        self.simulator = self.Simulator(diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self.n = 0
        self.body_plate, self.joints = plate, joints
        self.h = h
        self.inspector = _sg.model_inspector()
        self.sg = _sg

    def pose(self):
        """(x, y, z, yaw, ω_z, v_com, ω) of the plate."""
        plant, pc = self.plant, self.plant_context
        X = plant.EvalBodyPoseInWorld(pc, self.body_plate)
        V = plant.EvalBodySpatialVelocityInWorld(pc, self.body_plate)
        R = X.rotation().matrix()
        t = X.translation()
        w = V.rotational()
        return t, math.atan2(R[1, 0], R[0, 0]), float(w[2]), V.translational(), w

    def set_carriage(self, vx, vy):
        jx, jy, _, _ = self.joints
        jx.set_translation_rate(self.plant_context, vx)
        jy.set_translation_rate(self.plant_context, vy)

    def advance(self):
        # One plant update per call: the update at n h is taken by the call
        # that passes it; stopping just short of (n + 1) h leaves the next
        # one pending whatever the rounding of n h.
        self.n += 1
        self.simulator.AdvanceTo((self.n - 1e-6) * self.h)

    def rebuild(self, h):
        """A new plant with step h, the state carried over."""
        if self.joints is None:
            self.let_go(h)
            return
        q = self.plant.GetPositions(self.plant_context).copy()
        v = self.plant.GetVelocities(self.plant_context).copy()
        self.build(h)
        self.plant.SetPositions(self.plant_context, q)
        self.plant.SetVelocities(self.plant_context, v)

    def let_go(self, h, throw=None):
        """The plate alone (a free body, the pusher chain gone) in a new
        plant with step h, its pose and spatial velocity carried over;
        ``throw`` (vx, vy, omega) replaces its horizontal velocity and its
        spin about the vertical."""
        plant, pc = self.plant, self.plant_context
        X = plant.EvalBodyPoseInWorld(pc, self.body_plate)
        V = plant.EvalBodySpatialVelocityInWorld(pc, self.body_plate)
        w, v = V.rotational().copy(), V.translational().copy()
        if throw is not None:
            v[0], v[1], w[2] = throw
        from pydrake.multibody.math import SpatialVelocity

        self.build(h, released=True)
        self.plant.SetFreeBodyPose(self.plant_context, self.body_plate, X)
        self.plant.SetFreeBodySpatialVelocity(self.plant_context, self.body_plate, SpatialVelocity(w, v))

    # ------------------------------------------------------------------
    # Diagnostics

    def contacts(self):
        """Per foot: (normal force, tangential force (2), contact point (3))
        of the step just taken (the plant's output ports are sampled: they
        report the last update's solve); None where the foot is out of
        contact."""
        res = self.plant.get_contact_results_output_port().Eval(self.plant_context)
        out = [None] * len(self.foot_ids)
        index = {gid: k for k, gid in enumerate(self.foot_ids)}
        for i in range(res.num_point_pair_contacts()):
            info = res.point_pair_contact_info(i)
            pp = info.point_pair()
            k = index.get(pp.id_A, index.get(pp.id_B))
            if k is None:
                continue
            f = info.contact_force()  # on body B, world frame
            if self.plant.get_body(info.bodyB_index()).name() != "plate":
                f = -f
            out[k] = (float(f[2]), (float(f[0]), float(f[1])), info.contact_point())
        return out

    def record(self, t, before, after_state):
        """One diagnostics row per foot: the step's forces (``before``, from
        `contacts` after the step) against the slip at the step's end."""
        p = self.problem
        com, _yaw, _wz, vcom, w = after_state
        rise = float(com[2]) - self.rest_height
        total = sum(c[0] for c in before if c is not None)
        lost = 0
        for k, c in enumerate(before):
            sup = p.supports[k]
            if c is None or c[0] <= 0.0:
                lost += 1
                if self.diag:
                    self.diag.write(f"{self.problems},{self.settings.approximation},{self.h!r},{t!r},{k},0.0,"
                                    f"{sup.normal_force!r},0,,,,{rise!r},{total!r},{p.mass * p.gravity!r}\n")
                continue
            n, ft, pt = c
            r = [pt[0] - com[0], pt[1] - com[1], pt[2] - com[2]]
            vx = vcom[0] + w[1] * r[2] - w[2] * r[1]
            vy = vcom[1] + w[2] * r[0] - w[0] * r[2]
            slip = math.hypot(vx, vy)
            fmag = math.hypot(*ft)
            ratio = fmag / (sup.mu * n) if sup.mu > 0 else float("nan")
            err = ""
            if slip > 0 and fmag > 0:
                cosang = -(ft[0] * vx + ft[1] * vy) / (fmag * slip)
                err = repr(math.acos(max(-1.0, min(1.0, cosang))))
            self.stats_dir.append((slip, err))
            if self.diag:
                self.diag.write(f"{self.problems},{self.settings.approximation},{self.h!r},{t!r},{k},{n!r},"
                                f"{sup.normal_force!r},1,{slip!r},{ratio!r},{err},{rise!r},{total!r},"
                                f"{p.mass * p.gravity!r}\n")
        self.stats["steps"] += 1
        self.stats["lost_steps"] += 1 if lost else 0
        self.stats["max_rise"] = max(self.stats["max_rise"], rise)
        self.stats["max_load_error"] = max(self.stats["max_load_error"], abs(total - p.mass * p.gravity))

    # ------------------------------------------------------------------
    # The kit's two methods

    def reset(self, problem):
        self.problem = problem
        self.problems += 1
        self.settings = Settings(self.args, problem)
        self.build(problem.dt)
        plant, pc = self.plant, self.plant_context
        jx, jy, jz, ball = self.joints
        ini = problem.initial
        th = ini.theta
        px, py = ini.position
        rc = problem.contact_offset
        c, s = math.cos(th), math.sin(th)
        jx.set_translation(pc, px + c * rc[0] - s * rc[1])
        jy.set_translation(pc, py + s * rc[0] + c * rc[1])
        jz.set_translation(pc, -self.settings.penetration)
        ball.set_angles(pc, [0.0, 0.0, th])
        # 1. Settle at rest.
        for _ in range(math.ceil(SETTLE_TIME / self.h)):
            self.set_carriage(0.0, 0.0)
            self.advance()
        com, yaw, _wz, _v, _w = self.pose()
        self.rest_height = float(com[2])
        self.row_extras = self.extras_now(self.contacts(), com)
        self.stats = {"steps": 0, "lost_steps": 0, "max_rise": 0.0, "max_load_error": 0.0}
        self.stats_dir = []
        want_diag = self.diag is not None or self.args.check
        self.want_diag = want_diag
        if self.args.check:
            rest = self.contacts()
            w = problem.mass * problem.gravity
            tot = sum(x[0] for x in rest if x is not None)
            sys.stderr.write(f"drake_push.py --check: {self.settings.describe()}\n")
            sys.stderr.write(f"  rest: sum of normal loads {tot:.6g} N, m g {w:.6g} N "
                             f"(relative {abs(tot - w) / w:.2e}); rest height {self.rest_height:.6e} m\n")
            for k, (x, sup) in enumerate(zip(rest, problem.supports)):
                nk = x[0] if x is not None else 0.0
                sys.stderr.write(f"  foot {k}: load {nk:.6g} N, problem {sup.normal_force:.6g} N "
                                 f"(relative {abs(nk - sup.normal_force) / sup.normal_force:.2e}), mu {sup.mu}\n")
        # 2. The start: moving with the first push at ω, or at rest (the
        # first step's velocity change is then the start's switch).
        p0 = problem.pushes[0] if problem.pushes else None
        self.keep_omega = ini.from_rest and problem.switching == "continuous"
        # A plate thrown (no pushes) gets its initial velocity and ω at the
        # release, the first step.
        self.throw = (*ini.velocity, ini.omega) if p0 is None else None
        if p0 is None:
            w = ini.omega
        elif not ini.from_rest:
            w = ini.omega
            cvx, cvy = p0.world_velocity(yaw)
            self.set_carriage(cvx, cvy)
            ball.set_angular_velocity(pc, [0.0, 0.0, w])
        else:
            w = 0.0
        self.theta = ini.theta + math.remainder(yaw - ini.theta, 2 * math.pi)
        self.t = 0.0
        return State(float(com[0]), float(com[1]), self.theta, w)

    def switch(self, before, after):
        # Impulsive: the next step's velocity change keeps the angular
        # momentum about the contact point (what every step does);
        # continuous: ω is kept across it.
        self.keep_omega = self.problem.switching == "continuous"

    def drive(self, vx, vy):
        """Sets the carriage's velocity to (vx, vy) as a rigid pusher would:
        by an impulse at the contact point, which keeps the plate's angular
        momentum about that point, I_P ω − m (d × v_P)_z (d: contact point
        to centre of mass), unless ω is to be kept (continuous switching).
        The plate's velocity is relative to the carriage in the joint chain,
        so setting the carriage's alone would push through the centre of
        mass and miss the term m ω (ρ_c · v_p) of the pusher's turning."""
        jx, jy, _jz, ball = self.joints
        pc = self.plant_context
        ox, oy = jx.get_translation_rate(pc), jy.get_translation_rate(pc)
        if not self.keep_omega:
            p = self.problem
            com, _yaw, _wz, _v, _w = self.pose()
            dx = float(com[0]) - jx.get_translation(pc)
            dy = float(com[1]) - jy.get_translation(pc)
            i_p = p.inertia_cm + p.mass * (dx * dx + dy * dy)
            dw = -p.mass * (dx * (vy - oy) - dy * (vx - ox)) / i_p
            if dw != 0.0:
                w = ball.get_angular_velocity(pc).copy()
                w[2] += dw
                ball.set_angular_velocity(pc, w)
        self.keep_omega = False
        self.set_carriage(vx, vy)

    def step(self, push, h):
        if push is None and self.joints is not None:
            self.let_go(h, self.throw)
        elif abs(h - self.h) > 1e-12 * self.h:
            self.rebuild(h)
        if push is not None:
            _com, yaw, wz, _v, _w = self.pose()
            cvx, cvy = push.world_velocity(yaw + 0.5 * h * wz)
            self.drive(cvx, cvy)
        try:
            self.advance()
        except RuntimeError as e:
            raise AdapterError(f"Drake failed at t = {self.t:.6g} s: {e}") from None
        self.t += h
        state = self.pose()
        cts = self.contacts()
        self.row_extras = self.extras_now(cts, state[0])
        if self.want_diag:
            self.record(self.t, cts, state)
        com, yaw, wz, _v, _w = state
        self.theta += math.remainder(yaw - self.theta, 2 * math.pi)
        return State(float(com[0]), float(com[1]), self.theta, wz)

    def extras_now(self, cts, com):
        """load_1..load_n and rise for the step whose contacts are ``cts``
        and whose centre of mass ends at ``com``."""
        loads = [c[0] if c is not None else 0.0 for c in cts]
        return (*loads, float(com[2]) - self.rest_height)

    def extra_columns(self, problem):
        return (*(f"load_{i + 1}" for i in range(len(problem.supports))), "rise")

    def extras(self):
        return self.row_extras

    def close(self):
        if getattr(self, "want_diag", False) and getattr(self, "stats", None) and self.stats["steps"]:
            st = self.stats
            errs = [float(e) for s, e in self.stats_dir if e != "" and s > 10 * self.settings.stiction_tolerance]
            sys.stderr.write(
                f"drake_push.py: {st['steps']} steps, max rise {st['max_rise']:.3e} m, "
                f"steps with a foot out of contact {st['lost_steps'] / st['steps']:.4f}, "
                f"max |sum N - m g| {st['max_load_error']:.3e} N, "
                f"max friction direction error (slip > 10 v_s) {max(errs) if errs else float('nan'):.3e} rad\n")
        if self.diag:
            self.diag.flush()


if __name__ == "__main__":
    main(DrakePush)
