//! Island padding: texels outside every UV island take the mean of their filled neighbours, one
//! ring per pass, so that mipmaps and bilinear filtering near an island's border read the island's
//! own normals instead of the background.
//!
//! Each pass reads only texels filled before it, so the result does not depend on the order
//! texels are visited in.

/// Fills up to `passes` rings of empty texels around the filled ones. `normals` holds unit vectors
/// where `filled` is set; returns how many texels were filled.
pub fn pad(w: usize, h: usize, normals: &mut [[f32; 3]], filled: &mut [bool], passes: usize) -> usize {
    let neighbours = |i: usize| {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)].into_iter().filter_map(
            move |(dx, dy)| {
                let (nx, ny) = (x + dx, y + dy);
                (nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h).then(|| ny as usize * w + nx as usize)
            },
        )
    };
    let mut front: Vec<usize> = (0..w * h).filter(|&i| !filled[i] && neighbours(i).any(|j| filled[j])).collect();
    let mut total = 0;
    let mut queued = vec![false; w * h];
    for _ in 0..passes {
        if front.is_empty() {
            break;
        }
        let values: Vec<[f32; 3]> = front
            .iter()
            .map(|&i| {
                let mut s = [0.0f32; 3];
                for j in neighbours(i).filter(|&j| filled[j]) {
                    (0..3).for_each(|c| s[c] += normals[j][c]);
                }
                let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
                if l > 1e-6 {
                    [s[0] / l, s[1] / l, s[2] / l]
                } else {
                    [0.0, 0.0, 1.0]
                }
            })
            .collect();
        for (&i, v) in front.iter().zip(&values) {
            normals[i] = *v;
            filled[i] = true;
        }
        total += front.len();
        let mut next = Vec::new();
        for &i in &front {
            for j in neighbours(i) {
                if !filled[j] && !queued[j] {
                    queued[j] = true;
                    next.push(j);
                }
            }
        }
        for &j in &next {
            queued[j] = false;
        }
        next.sort_unstable();
        front = next;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_one_ring_per_pass_with_neighbour_means() {
        let (w, h) = (9, 9);
        let mut n = vec![[0.0, 0.0, 1.0]; w * h];
        let mut f = vec![false; w * h];
        let c = 4 * w + 4;
        n[c] = [0.6, 0.0, 0.8];
        f[c] = true;
        assert_eq!(pad(w, h, &mut n, &mut f, 2), 8 + 16);
        assert_eq!(n[3 * w + 3], [0.6, 0.0, 0.8]);
        assert!(!f[0] && f[2 * w + 2]);
        assert_eq!(pad(w, h, &mut n, &mut f, 100), 81 - 25);
        assert!(f.iter().all(|&x| x));
        assert!(n.iter().all(|v| (v[0] - 0.6).abs() < 1e-6));
    }
}
