//! The node tree, walked one way for every stage: which meshes a scene shows and where.

use super::Scene;
use glam::{DVec3, Mat3, Mat4, Quat, Vec3};
use serde_json::Value;

/// One place a mesh is shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    pub mesh: usize,
    /// The node that shows it; `None` for a file without nodes (every mesh shown at identity).
    pub node: Option<usize>,
    /// Object to world: the product of the node's transform and all its parents'.
    pub world: Mat4,
}

impl Instance {
    /// The matrix directions on the surface (tangents) go through: the world matrix without its
    /// translation. Renderers normalise what comes out.
    pub fn tangent_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.world)
    }

    /// The matrix normals go through: the inverse transpose of [`Self::tangent_matrix`] (itself
    /// when that cannot be inverted), so normals stay normal to a non-uniformly scaled surface.
    pub fn normal_matrix(&self) -> Mat3 {
        let m3 = self.tangent_matrix();
        let det = m3.determinant();
        if det.abs() > 1e-30 && det.is_finite() {
            m3.inverse().transpose()
        } else {
            m3
        }
    }

    /// Whether this instance mirrors its mesh (negative determinant), flipping winding and the
    /// bitangent sign a renderer must use.
    pub fn mirrored(&self) -> bool {
        self.tangent_matrix().determinant() < 0.0
    }

    /// The handedness `w` of a frame as the world sees it: negated on a mirroring instance, so
    /// that `B = cross(N, T) * w` still points along the texture's +v.
    pub fn world_w(&self, w: f32) -> f32 {
        if self.mirrored() {
            -w
        } else {
            w
        }
    }

    /// The instance's matrices, worked out once, for placing many vertices.
    pub fn placement(&self) -> Placement {
        Placement {
            world: self.world,
            tangent: self.tangent_matrix(),
            normal: self.normal_matrix(),
            mirrored: self.mirrored(),
        }
    }
}

impl Scene {
    /// Node `n`'s name, if it has one: the one reading of names the reports use.
    pub fn node_name(&self, n: usize) -> Option<&str> {
        self.array("nodes").get(n)?.get("name")?.as_str()
    }

    /// Mesh `m`'s name, if it has one.
    pub fn mesh_name(&self, m: usize) -> Option<&str> {
        self.array("meshes").get(m)?.get("name")?.as_str()
    }
}

/// How geometry is placed in the world by an [`Instance`]: the one place positions, normals,
/// tangents and winding are moved there (HIGH's reader, LOW for the baker, the preview). What
/// comes out is not normalised: each caller normalises in the precision it works in.
#[derive(Debug, Clone, Copy)]
pub struct Placement {
    world: Mat4,
    tangent: Mat3,
    normal: Mat3,
    mirrored: bool,
}

impl Placement {
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.world.transform_point3(p)
    }

    /// [`Self::point`] in f64, for a caller that moves points far from the origin into a frame
    /// of its own before they become f32 (the baker).
    pub fn point_f64(&self, p: DVec3) -> DVec3 {
        self.world.as_dmat4().transform_point3(p)
    }

    /// A normal's direction in the world (by [`Instance::normal_matrix`]).
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.normal * n
    }

    /// A tangent's direction in the world and its `w` ([`Instance::world_w`]).
    pub fn tangent(&self, t: [f32; 4]) -> (Vec3, f32) {
        (self.tangent * Vec3::new(t[0], t[1], t[2]), if self.mirrored { -t[3] } else { t[3] })
    }

    /// A triangle wound so that its front stays where its normals point: a mirroring transform
    /// turns counter-clockwise into clockwise, and swapping two corners turns it back.
    pub fn triangle(&self, t: [u32; 3]) -> [u32; 3] {
        if self.mirrored {
            [t[0], t[2], t[1]]
        } else {
            t
        }
    }

    pub fn mirrored(&self) -> bool {
        self.mirrored
    }
}

/// Every mesh the scene shows, once per node that shows it, with its world transform, in the
/// order of a depth-first walk of the default scene's node trees (every root node when there is
/// no scene, every mesh at identity when there are no nodes).
pub fn instances(scene: &Scene) -> Vec<Instance> {
    let j = &scene.json;
    let nodes = j.get("nodes").and_then(|n| n.as_array()).map(|n| n.as_slice()).unwrap_or(&[]);
    let roots: Vec<usize> = if let Some(sc) = j.get("scenes").and_then(|s| s.as_array()).filter(|s| !s.is_empty()) {
        let si = j.get("scene").and_then(|s| s.as_u64()).unwrap_or(0) as usize;
        let sc = sc.get(si).or(sc.first());
        sc.and_then(|s| s.get("nodes"))
            .and_then(|n| n.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_u64()).map(|x| x as usize).collect())
            .unwrap_or_default()
    } else if !nodes.is_empty() {
        let mut child = vec![false; nodes.len()];
        for n in nodes {
            for c in n.get("children").and_then(|c| c.as_array()).into_iter().flatten().filter_map(|c| c.as_u64()) {
                if let Some(x) = child.get_mut(c as usize) {
                    *x = true;
                }
            }
        }
        (0..nodes.len()).filter(|&i| !child[i]).collect()
    } else {
        let meshes = j.get("meshes").and_then(|m| m.as_array()).map(|m| m.len()).unwrap_or(0);
        return (0..meshes).map(|m| Instance { mesh: m, node: None, world: Mat4::IDENTITY }).collect();
    };
    let mut out = Vec::new();
    let mut stack: Vec<(usize, Mat4, usize)> = roots.into_iter().rev().map(|r| (r, Mat4::IDENTITY, 0)).collect();
    while let Some((n, parent, depth)) = stack.pop() {
        // glTF node graphs are trees; a cyclic or absurdly deep file must not hang the walk.
        let Some(node) = nodes.get(n) else { continue };
        if depth > 64 || out.len() > 1_000_000 {
            continue;
        }
        let world = parent * local_matrix(node);
        if let Some(m) = node.get("mesh").and_then(|m| m.as_u64()) {
            out.push(Instance { mesh: m as usize, node: Some(n), world });
        }
        let children: Vec<usize> = node
            .get("children")
            .and_then(|c| c.as_array())
            .into_iter()
            .flatten()
            .filter_map(|c| c.as_u64())
            .map(|c| c as usize)
            .collect();
        for c in children.into_iter().rev() {
            stack.push((c, world, depth + 1));
        }
    }
    out
}

fn floats(v: Option<&Value>, n: usize) -> Option<Vec<f32>> {
    let a = v?.as_array()?;
    let f: Vec<f32> = a.iter().map(|x| x.as_f64().map(|x| x as f32)).collect::<Option<_>>()?;
    (f.len() == n && f.iter().all(|x| x.is_finite())).then_some(f)
}

/// A node's own transform: `matrix`, else translation * rotation * scale (non-finite parts ignored).
pub fn local_matrix(node: &Value) -> Mat4 {
    if let Some(m) = floats(node.get("matrix"), 16) {
        return Mat4::from_cols_slice(&m);
    }
    let t = floats(node.get("translation"), 3).map(|v| Vec3::from_slice(&v)).unwrap_or(Vec3::ZERO);
    let r = floats(node.get("rotation"), 4)
        .map(|v| Quat::from_slice(&v).normalize())
        .filter(|q| q.is_finite())
        .unwrap_or(Quat::IDENTITY);
    let s = floats(node.get("scale"), 3).map(|v| Vec3::from_slice(&v)).unwrap_or(Vec3::ONE);
    Mat4::from_scale_rotation_translation(s, r, t)
}
