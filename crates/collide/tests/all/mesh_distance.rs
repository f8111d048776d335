//! The world's distance between a triangle mesh and a convex solid (its
//! own BVH traversal, pruning nodes by their boxes) against the brute
//! force: the least distance from the solid to every triangle.

use crate::common;

use kinpost_collide::shapes::to_pose;
use kinpost_collide::{Motion, World};
use kinpost_machine::{Body, Machine, Role, Shape, Solid, machine_from_toml};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::Vector;
use parry3d_f64::query;
use parry3d_f64::shape::{Ball, Cuboid, Triangle};
use proptest::prelude::*;

/// Three linear axes on the head; no solids of its own.
fn gantry() -> Machine {
    let axis = |n: &str, d: &str| {
        format!("[[axis]]\nname = \"{n}\"\nkind = \"linear\"\nside = \"tool\"\ndirection = {d}\n")
    };
    let src = format!(
        "name = \"g\"\n{}{}{}[tool]\npoint = [0, 0, 0]\naxis = [0, 0, 1]\n[collision]\nwarning_clearance = 1000\n",
        axis("X", "[1, 0, 0]"),
        axis("Y", "[0, 1, 0]"),
        axis("Z", "[0, 0, 1]")
    );
    machine_from_toml(&src, "g.toml").unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn mesh_distance_is_the_least_over_its_triangles(
        kind in 0usize..3,
        size in 1.0..40.0f64,
        at in proptest::array::uniform3(-80.0..80.0f64),
        axis in proptest::array::uniform3(-1.0..1.0f64),
        angle in -3.0..3.0f64,
        wave in 0.0..3.0f64,
    ) {
        let m = gantry();
        let mut world = World::new(&m).unwrap();
        let mesh = common::slab([-60.0, 60.0], [-40.0, 40.0], [-10.0, 0.0], 13, 9, wave);
        world.add_part("part", mesh.clone()).unwrap();
        let shape = match kind {
            0 => Shape::Sphere { radius_mm: size },
            1 => Shape::Box { size_mm: [size, 0.5 * size + 1.0, 2.0 * size] },
            _ => Shape::Cone { radius_bottom_mm: size, radius_top_mm: 0.3 * size, height_mm: 20.0 },
        };
        let axis = Vector3::from(axis);
        let rotation = if axis.norm() > 1e-3 {
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
        } else {
            UnitQuaternion::identity()
        };
        let home = Isometry3::from_parts(Translation3::new(at[0], at[1], at[2]), rotation);
        world.add_solid(Solid {
            name: "probe".into(),
            on: Body::Tool,
            shape: shape.clone(),
            home,
            group: "probe".into(),
            role: Role::Machine,
        }).unwrap();
        let reported = world
            .check_pose(&[0.0, 0.0, 0.0], Motion::Rapid)
            .first()
            .map(|c| c.distance_mm);
        // The brute force, with parry's shapes built here.
        let pose = to_pose(&home);
        let (g, offset): (Box<dyn parry3d_f64::shape::Shape>, _) = match shape {
            Shape::Sphere { radius_mm } => (Box::new(Ball::new(radius_mm)), parry3d_f64::math::Pose::IDENTITY),
            Shape::Box { size_mm } => (
                Box::new(Cuboid::new(Vector::new(size_mm[0] / 2.0, size_mm[1] / 2.0, size_mm[2] / 2.0))),
                parry3d_f64::math::Pose::from_translation(Vector::new(0.0, 0.0, size_mm[2] / 2.0)),
            ),
            // The frustum is the world's own hull: spheres and boxes test the
            // traversal.
            _ => return Ok(()),
        };
        let pose = pose * offset;
        let v = |i: u32| {
            let p = mesh.vertices[i as usize];
            Vector::new(p[0], p[1], p[2])
        };
        let brute = mesh
            .triangles
            .iter()
            .map(|t| {
                let tri = Triangle::new(v(t[0]), v(t[1]), v(t[2]));
                query::distance(&parry3d_f64::math::Pose::IDENTITY, &tri, &pose, &*g).unwrap().distance
            })
            .fold(f64::INFINITY, f64::min);
        match reported {
            Some(d) if d > 0.0 => prop_assert!((d - brute).abs() < 1e-6, "{d} vs {brute}"),
            // Touching, or wholly inside the closed slab (its centre inside
            // the slab's box, no triangle met).
            Some(_) => prop_assert!(
                brute < 1e-9
                    || (at[0].abs() < 60.0 && at[1].abs() < 40.0 && (-10.0..3.0).contains(&at[2])),
                "0 reported, brute force {brute}"
            ),
            None => prop_assert!(brute > 1000.0, "missed: brute force {brute}"),
        }
    }
}
