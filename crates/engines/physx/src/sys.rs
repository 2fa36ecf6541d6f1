//! The PhysX calls the `physx` crate has no safe wrapper for, each behind a
//! safe function: a shape's local pose, the pusher's D6 joint and its force,
//! the contact-reporting filter shader, reading a contact pair's normal
//! impulses, and releasing a scene's CPU dispatcher. This is the crate's only
//! `unsafe` code.

use physx::traits::Class;
use physx_sys::{
    FilterShaderCallbackInfo, PxContactPair, PxContactPairPoint, PxD6Axis, PxD6Motion,
    PxFilterFlags, PxPairFlags,
};

/// Sets the pose of `shape` relative to its actor.
pub(crate) fn set_local_pose(
    shape: &mut impl Class<physx_sys::PxShape>,
    pose: physx_sys::PxTransform,
) {
    // SAFETY: the pointer comes from a live shape owned by the caller; PhysX
    // copies the pose.
    unsafe { physx_sys::PxShape_setLocalPose_mut(shape.as_mut_ptr(), &pose) }
}

/// A `PxD6Joint` between the kinematic pusher (actor 0) and the object
/// (actor 1) that locks X and Y of actor 0's frame and leaves Z and the three
/// rotations free. Released on drop, which must come before the scene's.
pub(crate) struct D6Joint {
    joint: *mut physx_sys::PxD6Joint,
}

impl D6Joint {
    /// Creates the joint; `None` if PhysX refuses. The frames are in each
    /// actor's frame.
    pub(crate) fn new(
        physics: &mut impl Class<physx_sys::PxPhysics>,
        pusher: &mut impl Class<physx_sys::PxRigidActor>,
        frame0: physx_sys::PxTransform,
        object: &mut impl Class<physx_sys::PxRigidActor>,
        frame1: physx_sys::PxTransform,
    ) -> Option<Self> {
        // SAFETY: physics and both actors are live PhysX objects (the caller
        // holds them); the frames are copied. A null result is handled.
        let joint = unsafe {
            physx_sys::phys_PxD6JointCreate(
                physics.as_mut_ptr(),
                pusher.as_mut_ptr(),
                &frame0,
                object.as_mut_ptr(),
                &frame1,
            )
        };
        if joint.is_null() {
            return None;
        }
        for (axis, motion) in [
            (PxD6Axis::X, PxD6Motion::Locked),
            (PxD6Axis::Y, PxD6Motion::Locked),
            (PxD6Axis::Z, PxD6Motion::Free),
            (PxD6Axis::Twist, PxD6Motion::Free),
            (PxD6Axis::Swing1, PxD6Motion::Free),
            (PxD6Axis::Swing2, PxD6Motion::Free),
        ] {
            // SAFETY: `joint` is the non-null joint just created.
            unsafe { physx_sys::PxD6Joint_setMotion_mut(joint, axis, motion) };
        }
        Some(Self { joint })
    }

    /// The linear force (N, world frame) the joint last applied to actor 0
    /// (the pusher); the object feels its opposite.
    pub(crate) fn force_on_pusher(&self) -> [f64; 3] {
        let mut linear = physx_sys::PxVec3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        };
        let mut angular = linear;
        // SAFETY: the joint is live until drop; it owns its constraint, and
        // the outputs are local values.
        unsafe {
            let c = physx_sys::PxJoint_getConstraint(self.joint as *const physx_sys::PxJoint);
            if !c.is_null() {
                physx_sys::PxConstraint_getForce(c, &mut linear, &mut angular);
            }
        }
        [linear.x as f64, linear.y as f64, linear.z as f64]
    }
}

impl Drop for D6Joint {
    fn drop(&mut self) {
        // SAFETY: created non-null in `new`, released exactly once here.
        unsafe { physx_sys::PxJoint_release_mut(self.joint as *mut physx_sys::PxJoint) }
    }
}

/// The pair flags of every pair: it collides and reports its contact points
/// (with their impulses) every step it touches.
const REPORT: PxPairFlags = PxPairFlags::SolveContact
    .union(PxPairFlags::DetectDiscreteContact)
    .union(PxPairFlags::NotifyTouchFound)
    .union(PxPairFlags::NotifyTouchPersists)
    .union(PxPairFlags::NotifyContactPoints);

/// The `word3` bit of a shape's simulation filter data that keeps its
/// contact pairs out of PhysX's constraint welding.
pub(crate) const UNWELDED: u32 = 1;

/// The filter shader of every scene: every pair collides and reports its
/// contact points (with their impulses) every step it touches ([`REPORT`]);
/// a pair with a shape whose filter data has [`UNWELDED`] in `word3` is also
/// marked `eMODIFY_CONTACTS`. PhysX welds the contact pairs of one pair of
/// bodies into one solver constraint unless a pair's contacts are modifiable
/// (`DyDynamics.cpp`, `manager->isChangeable()`); with no contact-modify
/// callback set, nothing modifies them. (One shader for all scenes: physx-sys
/// keeps the first custom shader a process registers for every later scene.)
///
/// # Safety
/// Called by PhysX with a valid `info` whose `pairFlags` points to the pair's
/// flags.
pub(crate) unsafe extern "C" fn report_contacts(
    info: *mut FilterShaderCallbackInfo,
) -> PxFilterFlags {
    // SAFETY: see the function's contract.
    unsafe {
        let info = &mut *info;
        let unwelded = (info.filterData0.word3 | info.filterData1.word3) & UNWELDED != 0;
        *info.pairFlags = if unwelded {
            REPORT | PxPairFlags::ModifyContacts
        } else {
            REPORT
        };
    }
    PxFilterFlags::empty()
}

/// The sum of the normal impulses (N s) of `pair`'s contact points.
pub(crate) fn normal_impulse(pair: &PxContactPair) -> f64 {
    const MAX: usize = 16;
    let mut buf = [PxContactPairPoint {
        position: physx_sys::PxVec3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
        separation: 0.0,
        normal: physx_sys::PxVec3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
        internalFaceIndex0: 0,
        impulse: physx_sys::PxVec3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
        internalFaceIndex1: 0,
    }; MAX];
    // SAFETY: `pair` is a contact pair PhysX handed to the contact report
    // callback (valid during it); the buffer holds MAX points and PhysX
    // writes at most that many.
    let n = unsafe { physx_sys::PxContactPair_extractContacts(pair, buf.as_mut_ptr(), MAX as u32) };
    buf[..(n as usize).min(MAX)]
        .iter()
        .map(|p| {
            let i = p.impulse;
            let m = p.normal;
            (i.x * m.x + i.y * m.y + i.z * m.z).abs() as f64
        })
        .sum()
}

/// The scene's CPU dispatcher, to be released after the scene.
pub(crate) struct Dispatcher(*mut physx_sys::PxCpuDispatcher);

impl Dispatcher {
    /// The dispatcher `scene` runs on (created by the `physx` crate's scene
    /// descriptor, which never releases it).
    pub(crate) fn of(scene: &impl Class<physx_sys::PxScene>) -> Self {
        // SAFETY: the scene is live; the call only reads a pointer.
        Self(unsafe { physx_sys::PxScene_getCpuDispatcher(scene.as_ptr()) })
    }

    /// Releases the dispatcher; call only once the scene is gone.
    pub(crate) fn release(self) {
        if !self.0.is_null() {
            // SAFETY: the `physx` crate creates it with
            // PxDefaultCpuDispatcherCreate; the scene that used it is released.
            unsafe {
                physx_sys::PxDefaultCpuDispatcher_release_mut(
                    self.0 as *mut physx_sys::PxDefaultCpuDispatcher,
                )
            }
        }
    }
}
