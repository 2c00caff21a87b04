//! Mitsuba's binary grid-volume file (`.vol`, the format of the `gridvolume` plugin page), as
//! the `sdfgrid` shape reads it: the bytes `VOL`, version 3, the encoding (1: `f32`), the
//! resolution `x, y, z` and channel count as little-endian `i32`, a bounding box of six `f32`
//! (which the sdfgrid ignores), then the values with the channel fastest, then `x`, `y`, `z`.

use std::io::Read;
use std::path::Path;

use glam::Affine3A;
use restir_geometry::{SdfGrid, SdfNormals};

/// Counts memory against the build's budget: `(kept bytes, transient bytes, what)`.
pub(crate) type Take<'a> = dyn FnMut(u64, u64, &dyn Fn() -> String) -> Result<(), String> + 'a;

/// The `sdfgrid` of the file at `path` placed by `to_world`. `take(kept, transient, what)`
/// counts memory against the build's budget: the values before they are read, the voxels' BVH
/// entries before the BVH is built.
pub(crate) fn load_sdfgrid(
    path: &Path,
    to_world: Affine3A,
    normals: SdfNormals,
    take: &mut Take,
) -> Result<SdfGrid, String> {
    let name = || format!("sdfgrid '{}'", path.display());
    let h = read_vol_header(path)?;
    if h.channels != 1 {
        return Err(format!(
            "{} has {} channels, an sdfgrid needs 1 (as in Mitsuba 3)",
            name(),
            h.channels
        ));
    }
    let [x, y, z] = h.res;
    if x != y || y != z {
        return Err(format!(
            "{} is {x}×{y}×{z}: only grids with as many values on each axis are supported \
             (Mitsuba 3 mixes up the axes' voxel sizes otherwise)",
            name()
        ));
    }
    take(4 * h.values(), 4 * h.values(), &|| {
        format!("{} ({x}×{y}×{z} values)", name())
    })?;
    let (_, values) = read_vol(path)?;
    let grid =
        SdfGrid::new(x, values, to_world, normals).map_err(|e| format!("{}: {e}", name()))?;
    let voxels = grid.voxel_count() as u64;
    take(
        voxels * crate::desc::limits::MESH_BYTES_PER_TRIANGLE,
        0,
        &|| format!("{} ({voxels} voxels holding surface)", name()),
    )?;
    Ok(grid)
}

/// The header of a `.vol` file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct VolHeader {
    /// Values per axis `x, y, z`.
    pub res: [u32; 3],
    /// Values per grid point.
    pub channels: u32,
}

impl VolHeader {
    /// The number of values the file holds.
    pub(crate) fn values(&self) -> u64 {
        self.res.iter().map(|&r| r as u64).product::<u64>() * self.channels as u64
    }
}

const HEADER_BYTES: usize = 48;

fn parse_header(b: &[u8], path: &Path) -> Result<VolHeader, String> {
    let name = path.display();
    if b.len() < HEADER_BYTES || &b[..3] != b"VOL" {
        return Err(format!(
            "'{name}' is not a Mitsuba grid volume (.vol) file: it does not start with 'VOL'"
        ));
    }
    if b[3] != 3 {
        return Err(format!(
            "'{name}': grid volume version {} is not supported (only version 3)",
            b[3]
        ));
    }
    let int = |i: usize| i32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let encoding = int(4);
    if encoding != 1 {
        return Err(format!(
            "'{name}': grid volume encoding {encoding} is not supported (only 1, 32-bit floats, \
             as in Mitsuba 3)"
        ));
    }
    let dims = [int(8), int(12), int(16), int(20)];
    if let Some(bad) = dims.iter().find(|&&d| d <= 0) {
        return Err(format!(
            "'{name}': grid volume resolution and channel count must be positive, found {bad}"
        ));
    }
    Ok(VolHeader {
        res: [dims[0] as u32, dims[1] as u32, dims[2] as u32],
        channels: dims[3] as u32,
    })
}

/// Reads the header alone (to count the memory before the values are read).
pub(crate) fn read_vol_header(path: &Path) -> Result<VolHeader, String> {
    let mut f = std::fs::File::open(path)
        .map_err(|e| format!("cannot open grid volume '{}': {e}", path.display()))?;
    let mut b = [0u8; HEADER_BYTES];
    f.read_exact(&mut b).map_err(|_| {
        format!(
            "'{}' is too short for a grid volume (.vol) header",
            path.display()
        )
    })?;
    parse_header(&b, path)
}

/// Reads a whole `.vol` file: its header and values.
pub(crate) fn read_vol(path: &Path) -> Result<(VolHeader, Vec<f32>), String> {
    let header = read_vol_header(path)?;
    let want = header.values();
    let len = std::fs::metadata(path)
        .map_err(|e| format!("cannot read grid volume '{}': {e}", path.display()))?
        .len();
    if len != HEADER_BYTES as u64 + 4 * want {
        return Err(format!(
            "grid volume '{}' is {len} bytes, but its header ({}×{}×{}, {} channel(s)) needs {}",
            path.display(),
            header.res[0],
            header.res[1],
            header.res[2],
            header.channels,
            HEADER_BYTES as u64 + 4 * want
        ));
    }
    let bytes = std::fs::read(path)
        .map_err(|e| format!("cannot read grid volume '{}': {e}", path.display()))?;
    let values = bytes[HEADER_BYTES..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Ok((header, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vol(res: [i32; 3], channels: i32, values: &[f32]) -> Vec<u8> {
        let mut b = b"VOL\x03".to_vec();
        for v in [1, res[0], res[1], res[2], channels] {
            b.extend(v.to_le_bytes());
        }
        for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0].iter().chain(values) {
            b.extend(v.to_le_bytes());
        }
        b
    }

    #[test]
    fn reads_and_refuses() {
        let dir = restir_testkit::TempDir::new("volfile", "read");
        let p = dir.path().join("g.vol");
        let values: Vec<f32> = (0..8).map(|i| i as f32 - 3.5).collect();
        std::fs::write(&p, vol([2, 2, 2], 1, &values)).unwrap();
        let (h, v) = read_vol(&p).unwrap();
        assert_eq!(h.res, [2, 2, 2]);
        assert_eq!(v, values);
        // Truncated data.
        std::fs::write(&p, vol([2, 2, 3], 1, &values)).unwrap();
        let e = read_vol(&p).unwrap_err();
        assert!(e.contains("g.vol") && e.contains("needs"), "{e}");
        // Not a volume.
        std::fs::write(
            &p,
            b"PLY and more bytes than a header has, long enough to read",
        )
        .unwrap();
        let e = read_vol(&p).unwrap_err();
        assert!(e.contains("does not start with 'VOL'"), "{e}");
        // Another encoding.
        let mut b = vol([2, 2, 2], 1, &values);
        b[4] = 2;
        std::fs::write(&p, b).unwrap();
        assert!(read_vol(&p).unwrap_err().contains("encoding 2"));
    }
}
