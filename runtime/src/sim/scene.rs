//! Plain data describing a simulated world at one moment, for pictures.

use serde::{Deserialize, Serialize};

use super::Pose;

/// Where an object is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ObjectState {
    /// On the arena floor.
    Floor,
    /// In the gripper.
    Held,
    /// Thrown out of the arena (physical objects only; virtual ones reappear).
    Outside,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneObject {
    /// Centre, mm (a held object is drawn in the gripper, in front of the body).
    pub x: f32,
    pub y: f32,
    pub radius: f32,
    pub virtual_: bool,
    pub state: ObjectState,
}

/// A snapshot of the world: arena, charger, lamp, objects and robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Width (x) and depth (y), mm; origin at the south-west corner.
    pub arena: [f32; 2],
    /// The charger bar's end points, if there is a charger.
    pub bar: Option<[[f32; 2]; 2]>,
    /// The lamp's position (above the bar's middle), if there is one.
    pub lamp: Option<[f32; 2]>,
    pub objects: Vec<SceneObject>,
    /// Inner walls' end points.
    #[serde(default)]
    pub walls: Vec<[[f32; 2]; 2]>,
    /// Cylinders: centre x, y and radius.
    #[serde(default)]
    pub cylinders: Vec<[f32; 3]>,
    /// Declared lamps (the charger's is `lamp`).
    #[serde(default)]
    pub lamps: Vec<[f32; 2]>,
    /// The indices in `lamps` of the lamps that are off (intensity 0).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dark_lamps: Vec<usize>,
    #[serde(default)]
    pub zones: Vec<SceneZone>,
    pub pose: Pose,
    pub body_radius: f32,
    pub arm_down: bool,
    pub claw_closed: bool,
}

/// A floor zone: south-west and north-east corners, grey level, charger.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneZone {
    pub from: [f32; 2],
    pub to: [f32; 2],
    pub grey: f32,
    pub charger: bool,
}
