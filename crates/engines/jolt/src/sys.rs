//! The crate's only `unsafe` code: a small safe wrapper over the joltc calls
//! the scene needs (oxijolt-sys is raw FFI). Every block states why its
//! call is sound. joltc's rules (oxijolt-sys's crate docs): `JPH_Init` once
//! per process; creating and destroying physics systems one thread at a
//! time; `JPH_PhysicsSystem_Destroy` deletes the three layer objects handed
//! to it; shape creators return one reference, which bodies add to.

use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError};

use oxijolt_sys::*;

const OL_FLOOR: JPH_ObjectLayer = 0;
const OL_OBJECT: JPH_ObjectLayer = 1;
const OL_PUSHER: JPH_ObjectLayer = 2;

/// joltc's global state (`JPH_Init`, the system map) is unsynchronised:
/// every world holds this lock while it is created, stepped and destroyed.
static JOLT: Mutex<()> = Mutex::new(());

fn init() {
    static INIT: OnceLock<bool> = OnceLock::new();
    // SAFETY: `OnceLock` runs `JPH_Init` exactly once per process, so its
    // unsynchronised initialisation never races.
    let ok = *INIT.get_or_init(|| unsafe { JPH_Init() });
    assert!(ok, "JPH_Init failed");
}

fn v3(p: [f64; 3]) -> JPH_Vec3 {
    JPH_Vec3 {
        x: p[0] as f32,
        y: p[1] as f32,
        z: p[2] as f32,
    }
}

fn r3(p: [f64; 3]) -> JPH_RVec3 {
    JPH_RVec3 {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// A yaw quaternion.
fn yaw(theta: f64) -> JPH_Quat {
    let (s, c) = (0.5 * theta).sin_cos();
    JPH_Quat {
        x: 0.0,
        y: 0.0,
        z: s as f32,
        w: c as f32,
    }
}

/// The object's collider, in the body frame whose origin is the centre of
/// mass at ground-contact height (z = 0).
pub(crate) enum Collider {
    /// A box: centre (m) and half extents (m).
    Box { center: [f64; 3], half: [f64; 3] },
    /// Spheres: centres (m) and one radius (m).
    Spheres { centers: Vec<[f64; 3]>, radius: f64 },
}

/// What the world is built from.
pub(crate) struct Spec {
    pub collider: Collider,
    pub mass: f64,
    /// Principal inertia about the centre of mass (kg m²): x, y, z.
    pub inertia: [f64; 3],
    pub friction: f64,
    pub manifold_reduction: bool,
    pub gravity: f64,
    pub velocity_steps: u32,
    pub position_steps: u32,
    pub penetration_slop: f64,
    /// Convex radius of the floor box (m).
    pub floor_convex_radius: f64,
    /// Initial pose of the centre of mass (m) and yaw (rad).
    pub position: [f64; 3],
    pub theta: f64,
    /// Where the pusher holds the object (m, body frame).
    pub anchor: [f64; 3],
}

/// Pose and velocity of a body.
#[derive(Debug, Clone, Copy)]
pub struct BodyState {
    /// Centre of mass (m).
    pub com: [f64; 3],
    /// Rotation quaternion (x, y, z, w).
    pub rotation: [f64; 4],
    /// Linear velocity (m/s).
    pub linear: [f64; 3],
    /// Angular velocity (rad/s).
    pub angular: [f64; 3],
}

/// One Jolt physics system with a floor, the object and the pusher.
pub(crate) struct World {
    system: *mut JPH_PhysicsSystem,
    job_system: *mut JPH_JobSystem,
    temp: *mut JPH_TempAllocator,
    constraint: *mut JPH_SixDOFConstraint,
    pub object: JPH_BodyID,
    pub pusher: JPH_BodyID,
    pub floor: JPH_BodyID,
    _lock: MutexGuard<'static, ()>,
}

impl World {
    /// Builds the scene. `None` when joltc refuses something.
    pub fn new(spec: &Spec) -> Option<Self> {
        let lock = JOLT.lock().unwrap_or_else(PoisonError::into_inner);
        init();
        // SAFETY: Jolt is initialised and we hold the world lock. Every
        // pointer passed below comes from the matching `_Create` call just
        // before it; the three layer objects are handed to
        // `JPH_PhysicsSystem_Create`, which owns them from then on.
        let (system, job_system, temp) = unsafe {
            let pairs = JPH_ObjectLayerPairFilterTable_Create(3);
            JPH_ObjectLayerPairFilterTable_EnableCollision(pairs, OL_FLOOR, OL_OBJECT);
            let bpl = JPH_BroadPhaseLayerInterfaceTable_Create(3, 2);
            JPH_BroadPhaseLayerInterfaceTable_MapObjectToBroadPhaseLayer(bpl, OL_FLOOR, 0);
            JPH_BroadPhaseLayerInterfaceTable_MapObjectToBroadPhaseLayer(bpl, OL_OBJECT, 1);
            JPH_BroadPhaseLayerInterfaceTable_MapObjectToBroadPhaseLayer(bpl, OL_PUSHER, 1);
            let ovb = JPH_ObjectVsBroadPhaseLayerFilterTable_Create(bpl, 2, pairs, 3);
            let settings = JPH_PhysicsSystemSettings {
                maxBodies: 16,
                maxBodyPairs: 64,
                maxContactConstraints: 64,
                broadPhaseLayerInterface: bpl,
                objectLayerPairFilter: pairs,
                objectVsBroadPhaseLayerFilter: ovb,
                ..std::mem::zeroed()
            };
            let system = JPH_PhysicsSystem_Create(&settings);
            if system.is_null() {
                return None;
            }
            (
                system,
                JPH_JobSystemSingleThreaded_Create(2048),
                JPH_TempAllocator_Create(16 * 1024 * 1024),
            )
        };
        let mut world = World {
            system,
            job_system,
            temp,
            constraint: std::ptr::null_mut(),
            object: u32::MAX,
            pusher: u32::MAX,
            floor: u32::MAX,
            _lock: lock,
        };
        world.build(spec)?;
        Some(world)
    }

    fn build(&mut self, spec: &Spec) -> Option<()> {
        // SAFETY: `self.system` is live (checked non-null in `new`) and not
        // stepping; every settings pointer is a live local or comes from the
        // `_Create` just before and is destroyed after its last use. Shapes
        // are released after the bodies took their own references.
        unsafe {
            let mut ps: JPH_PhysicsSettings = std::mem::zeroed();
            JPH_PhysicsSystem_GetPhysicsSettings(self.system, &mut ps);
            ps.numVelocitySteps = spec.velocity_steps;
            ps.numPositionSteps = spec.position_steps;
            ps.penetrationSlop = spec.penetration_slop as f32;
            ps.allowSleeping = false;
            JPH_PhysicsSystem_SetPhysicsSettings(self.system, &mut ps);
            JPH_PhysicsSystem_SetGravity(self.system, &v3([0.0, 0.0, -spec.gravity]));
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);

            // Floor: a static box with its top face at z = 0.
            let floor_shape =
                JPH_BoxShape_Create(&v3([50.0, 50.0, 0.5]), spec.floor_convex_radius as f32);
            let s = JPH_BodyCreationSettings_Create3(
                floor_shape as *const JPH_Shape,
                &r3([0.0, 0.0, -0.5]),
                &yaw(0.0),
                JPH_MotionType_Static,
                OL_FLOOR,
            );
            JPH_BodyCreationSettings_SetFriction(s, spec.friction as f32);
            JPH_BodyCreationSettings_SetRestitution(s, 0.0);
            self.floor = JPH_BodyInterface_CreateAndAddBody(bi, s, JPH_Activation_DontActivate);
            JPH_BodyCreationSettings_Destroy(s);
            JPH_Shape_Destroy(floor_shape as *mut JPH_Shape);

            // Object: a compound of the collider, its centre of mass moved
            // to the body origin (ground-contact height).
            let compound = JPH_StaticCompoundShapeSettings_Create();
            let children: Vec<*mut JPH_Shape> = match &spec.collider {
                Collider::Box { center, half } => {
                    let b = JPH_BoxShape_Create(&v3(*half), 0.0) as *mut JPH_Shape;
                    JPH_CompoundShapeSettings_AddShape2(
                        compound as *mut JPH_CompoundShapeSettings,
                        &v3(*center),
                        &yaw(0.0),
                        b,
                        0,
                    );
                    vec![b]
                }
                Collider::Spheres { centers, radius } => centers
                    .iter()
                    .enumerate()
                    .map(|(i, c)| {
                        let b = JPH_SphereShape_Create(*radius as f32) as *mut JPH_Shape;
                        JPH_CompoundShapeSettings_AddShape2(
                            compound as *mut JPH_CompoundShapeSettings,
                            &v3(*c),
                            &yaw(0.0),
                            b,
                            i as u32,
                        );
                        b
                    })
                    .collect(),
            };
            let inner = JPH_StaticCompoundShape_Create(compound) as *mut JPH_Shape;
            JPH_ShapeSettings_Destroy(compound as *mut JPH_ShapeSettings);
            for b in children {
                JPH_Shape_Destroy(b);
            }
            if inner.is_null() {
                return None;
            }
            let mut c0 = v3([0.0; 3]);
            JPH_Shape_GetCenterOfMass(inner, &mut c0);
            let offset = JPH_Vec3 {
                x: -c0.x,
                y: -c0.y,
                z: -c0.z,
            };
            let shape = JPH_OffsetCenterOfMassShape_Create(&offset, inner) as *mut JPH_Shape;
            JPH_Shape_Destroy(inner);
            if shape.is_null() {
                return None;
            }
            let s = JPH_BodyCreationSettings_Create3(
                shape,
                &r3(spec.position),
                &yaw(spec.theta),
                JPH_MotionType_Dynamic,
                OL_OBJECT,
            );
            let mut mp: JPH_MassProperties = std::mem::zeroed();
            mp.mass = spec.mass as f32;
            mp.inertia.column[0].x = spec.inertia[0] as f32;
            mp.inertia.column[1].y = spec.inertia[1] as f32;
            mp.inertia.column[2].z = spec.inertia[2] as f32;
            mp.inertia.column[3].w = 1.0;
            JPH_BodyCreationSettings_SetMassPropertiesOverride(s, &mp);
            JPH_BodyCreationSettings_SetOverrideMassProperties(
                s,
                JPH_OverrideMassProperties_MassAndInertiaProvided,
            );
            JPH_BodyCreationSettings_SetLinearDamping(s, 0.0);
            JPH_BodyCreationSettings_SetAngularDamping(s, 0.0);
            JPH_BodyCreationSettings_SetAllowSleeping(s, false);
            JPH_BodyCreationSettings_SetFriction(s, spec.friction as f32);
            JPH_BodyCreationSettings_SetRestitution(s, 0.0);
            JPH_BodyCreationSettings_SetMaxAngularVelocity(s, 1.0e4);
            JPH_BodyCreationSettings_SetUseManifoldReduction(s, spec.manifold_reduction);
            let object = JPH_BodyInterface_CreateBody(bi, s);
            JPH_BodyCreationSettings_Destroy(s);
            JPH_Shape_Destroy(shape);
            if object.is_null() {
                return None;
            }
            self.object = JPH_Body_GetID(object);
            JPH_BodyInterface_AddBody(bi, self.object, JPH_Activation_Activate);

            // Pusher: a kinematic sphere that collides with nothing, at the
            // anchor's world position.
            let anchor = self.anchor_world(spec.position, spec.theta, spec.anchor);
            let ps_shape = JPH_SphereShape_Create(0.005);
            let s = JPH_BodyCreationSettings_Create3(
                ps_shape as *const JPH_Shape,
                &r3(anchor),
                &yaw(0.0),
                JPH_MotionType_Kinematic,
                OL_PUSHER,
            );
            JPH_BodyCreationSettings_SetAllowSleeping(s, false);
            let pusher = JPH_BodyInterface_CreateBody(bi, s);
            JPH_BodyCreationSettings_Destroy(s);
            JPH_Shape_Destroy(ps_shape as *mut JPH_Shape);
            if pusher.is_null() {
                return None;
            }
            self.pusher = JPH_Body_GetID(pusher);
            JPH_BodyInterface_AddBody(bi, self.pusher, JPH_Activation_Activate);

            // Six-DOF constraint: the two horizontal translations fixed,
            // everything else free.
            let mut cs: JPH_SixDOFConstraintSettings = std::mem::zeroed();
            JPH_SixDOFConstraintSettings_Init(&mut cs);
            cs.space = JPH_ConstraintSpace_WorldSpace;
            cs.position1 = r3(anchor);
            cs.position2 = r3(anchor);
            cs.axisX1 = v3([1.0, 0.0, 0.0]);
            cs.axisY1 = v3([0.0, 1.0, 0.0]);
            cs.axisX2 = v3([1.0, 0.0, 0.0]);
            cs.axisY2 = v3([0.0, 1.0, 0.0]);
            JPH_SixDOFConstraintSettings_MakeFixedAxis(
                &mut cs,
                JPH_SixDOFConstraintAxis_TranslationX,
            );
            JPH_SixDOFConstraintSettings_MakeFixedAxis(
                &mut cs,
                JPH_SixDOFConstraintAxis_TranslationY,
            );
            let c = JPH_SixDOFConstraint_Create(&cs, pusher, object);
            if c.is_null() {
                return None;
            }
            JPH_PhysicsSystem_AddConstraint(self.system, c as *mut JPH_Constraint);
            self.constraint = c;
            JPH_PhysicsSystem_OptimizeBroadPhase(self.system);
        }
        Some(())
    }

    /// World position (m) of the body-frame point `local` for a body whose
    /// centre of mass is at `com` with yaw `theta` (rad).
    pub fn anchor_world(&self, com: [f64; 3], theta: f64, local: [f64; 3]) -> [f64; 3] {
        let (s, c) = theta.sin_cos();
        [
            com[0] + c * local[0] - s * local[1],
            com[1] + s * local[0] + c * local[1],
            com[2] + local[2],
        ]
    }

    /// Advances by `dt` seconds (one collision step); false on an error.
    pub fn step(&mut self, dt: f64) -> bool {
        // SAFETY: the system, allocator and job system are live until drop.
        let r = unsafe {
            JPH_PhysicsSystem_Update2(self.system, dt as f32, 1, self.temp, self.job_system)
        };
        r == JPH_PhysicsUpdateError_None
    }

    /// Pose and velocity of `body`.
    pub fn state(&self, body: JPH_BodyID) -> BodyState {
        let mut p = r3([0.0; 3]);
        let mut q = yaw(0.0);
        let mut v = v3([0.0; 3]);
        let mut w = v3([0.0; 3]);
        // SAFETY: `body` is a body of this live system; the out pointers are
        // live locals.
        unsafe {
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);
            JPH_BodyInterface_GetCenterOfMassPosition(bi, body, &mut p);
            JPH_BodyInterface_GetRotation(bi, body, &mut q);
            JPH_BodyInterface_GetLinearVelocity(bi, body, &mut v);
            JPH_BodyInterface_GetAngularVelocity(bi, body, &mut w);
        }
        BodyState {
            com: [p.x, p.y, p.z],
            rotation: [q.x as f64, q.y as f64, q.z as f64, q.w as f64],
            linear: [v.x as f64, v.y as f64, v.z as f64],
            angular: [w.x as f64, w.y as f64, w.z as f64],
        }
    }

    /// Sets the linear and angular velocity of `body`.
    pub fn set_velocity(&mut self, body: JPH_BodyID, linear: [f64; 3], angular: [f64; 3]) {
        let mut w = v3(angular);
        // SAFETY: `body` is a body of this live system; the inputs are live
        // locals.
        unsafe {
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);
            JPH_BodyInterface_SetLinearVelocity(bi, body, &v3(linear));
            JPH_BodyInterface_SetAngularVelocity(bi, body, &mut w);
        }
    }

    /// Puts the pusher at `position` (m) and gives it `velocity` (m/s).
    pub fn drive_pusher(&mut self, position: [f64; 3], velocity: [f64; 3]) {
        // SAFETY: the pusher is a body of this live system; the inputs are
        // live locals.
        unsafe {
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);
            JPH_BodyInterface_SetPositionAndRotation(
                bi,
                self.pusher,
                &r3(position),
                &yaw(0.0),
                JPH_Activation_Activate,
            );
            JPH_BodyInterface_SetLinearVelocity(bi, self.pusher, &v3(velocity));
        }
    }

    /// Removes and destroys the pusher's six-DOF constraint (the object is
    /// then free of the pusher) and stops the pusher; nothing if it is gone
    /// already.
    pub fn release_pusher(&mut self) {
        // SAFETY: the constraint, when non-null, was added to this live
        // system in `build` and is removed and destroyed once here (the
        // pointer is nulled, so `drop` skips it); the pusher is a body of
        // this system and the input is a live local.
        unsafe {
            if !self.constraint.is_null() {
                JPH_PhysicsSystem_RemoveConstraint(
                    self.system,
                    self.constraint as *mut JPH_Constraint,
                );
                JPH_Constraint_Destroy(self.constraint as *mut JPH_Constraint);
                self.constraint = std::ptr::null_mut();
            }
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);
            JPH_BodyInterface_SetLinearVelocity(bi, self.pusher, &v3([0.0; 3]));
        }
    }

    /// The contact cache as `JPH_PhysicsSystem_SaveState` writes it (state
    /// `Contacts` only): the bytes [`crate::world`] parses.
    pub fn contact_state(&self) -> Vec<u8> {
        // SAFETY: the system is live and not stepping; null bodies with a
        // count of 0 save every body; the recorder is destroyed before
        // returning and `bytes` has exactly the size `CopyData` is told.
        unsafe {
            let rec = JPH_StateRecorder_Create();
            JPH_PhysicsSystem_SaveState(
                self.system,
                rec,
                JPH_StateRecorderState_Contacts,
                std::ptr::null(),
                0,
            );
            let mut bytes = vec![0_u8; JPH_StateRecorder_GetDataSize(rec)];
            JPH_StateRecorder_CopyData(rec, bytes.as_mut_ptr().cast(), bytes.len());
            let failed = JPH_StateRecorder_IsFailed(rec);
            JPH_StateRecorder_Destroy(rec);
            if failed {
                bytes.clear();
            }
            bytes
        }
    }
}

impl Drop for World {
    fn drop(&mut self) {
        // SAFETY: everything below was created in `new`/`build`, is
        // destroyed once, constraint and bodies before the system that holds
        // them; we still hold the world lock.
        unsafe {
            let bi = JPH_PhysicsSystem_GetBodyInterface(self.system);
            if !self.constraint.is_null() {
                JPH_PhysicsSystem_RemoveConstraint(
                    self.system,
                    self.constraint as *mut JPH_Constraint,
                );
                JPH_Constraint_Destroy(self.constraint as *mut JPH_Constraint);
            }
            for id in [self.pusher, self.object, self.floor] {
                if id != u32::MAX {
                    JPH_BodyInterface_RemoveAndDestroyBody(bi, id);
                }
            }
            JPH_PhysicsSystem_Destroy(self.system);
            JPH_JobSystem_Destroy(self.job_system);
            JPH_TempAllocator_Destroy(self.temp);
        }
    }
}
