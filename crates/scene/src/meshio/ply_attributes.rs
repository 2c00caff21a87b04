//! Which PLY properties become mesh attributes, and under which names, as Mitsuba 3's `ply`
//! plugin groups them (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_shapes.html#ply>):
//!
//! - `r, g, b` (or `red, green, blue`), with `a` (`alpha`) if present, anywhere in the element:
//!   one attribute `vertex_color` / `face_color` of 3 (4) channels;
//! - otherwise consecutive properties `{prefix}_{postfix}` whose one-letter postfixes run
//!   `x, y, z, w`, `r, g, b, a`, `0, 1, 2, 3` or `1, 2, 3, 4` from the start: one attribute
//!   `vertex_{prefix}` / `face_{prefix}` (`…_{prefix}_color` for the `r, g, b` run) when the run
//!   has 1 or 3 properties.
//!
//! Anything else (a name without `_`, a postfix longer than one letter, a run of 2 or 4, a
//! prefix seen before, a run out of order) is no attribute, as in Mitsuba (which warns). List
//! properties and the geometry's own properties (positions, normals, uvs, face indices) are
//! never attributes.

/// One attribute: its name and the element's properties that are its channels, in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Group {
    pub name: String,
    pub fields: Vec<usize>,
}

/// The postfixes of each run, channel by channel: `RUNS[run][channel]`.
const RUNS: [[char; 4]; 4] = [
    ['x', 'y', 'z', 'w'],
    ['r', 'g', 'b', 'a'],
    ['0', '1', '2', '3'],
    ['1', '2', '3', '4'],
];

/// Property names of the geometry itself that contain `_` (names without one are never
/// attributes anyway).
const RESERVED: [&str; 4] = ["texture_u", "texture_v", "texture_s", "texture_t"];

/// The attributes of an element whose properties are `props` (name, whether a list), named
/// with `kind` (`"vertex_"` or `"face_"`).
pub(super) fn groups<'p>(kind: &str, props: &[(&'p str, bool)]) -> Vec<Group> {
    let find = |n: &str| props.iter().position(|&(p, list)| p == n && !list);
    let mut out = Vec::new();
    let mut color: Vec<usize> = Vec::new();
    for names in [["r", "g", "b", "a"], ["red", "green", "blue", "alpha"]] {
        if let (Some(r), Some(g), Some(b)) = (find(names[0]), find(names[1]), find(names[2])) {
            color = vec![r, g, b];
            color.extend(find(names[3]));
            out.push(Group {
                name: format!("{kind}color"),
                fields: color.clone(),
            });
            break;
        }
    }

    let mut seen: Vec<&'p str> = Vec::new();
    let mut current: Run<'p> = None;
    // A prefix whose run went wrong: its remaining fields are skipped.
    let mut dropped: Option<&str> = None;
    for (i, &(name, list)) in props.iter().enumerate() {
        if list || color.contains(&i) || RESERVED.contains(&name) {
            continue;
        }
        let Some((prefix, postfix)) = name.rsplit_once('_') else {
            flush(kind, &mut current, &mut seen, &mut out);
            continue;
        };
        let mut chars = postfix.chars();
        let (Some(c), None) = (chars.next(), chars.next()) else {
            flush(kind, &mut current, &mut seen, &mut out);
            continue;
        };
        if dropped == Some(prefix) {
            continue;
        }
        dropped = None;
        if current.as_ref().is_some_and(|(p, ..)| *p != prefix) {
            flush(kind, &mut current, &mut seen, &mut out);
        }
        match &mut current {
            None => {
                if seen.contains(&prefix) {
                    continue;
                }
                if let Some(run) = RUNS.iter().position(|r| r[0] == c) {
                    current = Some((prefix, run, vec![i]));
                }
            }
            Some((_, run, fields)) => {
                if RUNS[*run].get(fields.len()) == Some(&c) {
                    fields.push(i);
                } else {
                    current = None;
                    dropped = Some(prefix);
                }
            }
        }
    }
    flush(kind, &mut current, &mut seen, &mut out);
    out
}

/// The run being read: its prefix, which of [`RUNS`], and its fields so far.
type Run<'p> = Option<(&'p str, usize, Vec<usize>)>;

/// Ends the run being read: an attribute if it has 1 or 3 fields.
fn flush<'p>(kind: &str, current: &mut Run<'p>, seen: &mut Vec<&'p str>, out: &mut Vec<Group>) {
    if let Some((prefix, run, fields)) = current.take()
        && (fields.len() == 1 || fields.len() == 3)
    {
        let suffix = if run == 1 { "_color" } else { "" };
        out.push(Group {
            name: format!("{kind}{prefix}{suffix}"),
            fields,
        });
        seen.push(prefix);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(kind: &str, props: &[&str]) -> Vec<(String, Vec<usize>)> {
        let p: Vec<(&str, bool)> = props.iter().map(|&n| (n, n == "vertex_indices")).collect();
        groups(kind, &p)
            .into_iter()
            .map(|g| (g.name, g.fields))
            .collect()
    }

    #[test]
    fn runs_and_colors_are_grouped_as_mitsuba_names_them() {
        // Mitsuba's own test mesh: numbered runs.
        assert_eq!(
            names(
                "vertex_",
                &[
                    "x", "y", "z", "nx", "ny", "nz", "u", "v", "color_0", "color_1", "color_2"
                ]
            ),
            vec![("vertex_color".into(), vec![8, 9, 10])]
        );
        assert_eq!(
            names(
                "face_",
                &[
                    "vertex_indices",
                    "color_0",
                    "color_1",
                    "color_2",
                    "weight_0"
                ]
            ),
            vec![
                ("face_color".into(), vec![1, 2, 3]),
                ("face_weight".into(), vec![4])
            ]
        );
        // Bare colours, in r, g, b order wherever they are; `_r, _g, _b` runs get `_color`.
        assert_eq!(
            names(
                "vertex_",
                &[
                    "x", "blue", "y", "z", "green", "red", "albedo_r", "albedo_g", "albedo_b"
                ]
            ),
            vec![
                ("vertex_color".into(), vec![5, 4, 1]),
                ("vertex_albedo_color".into(), vec![6, 7, 8]),
            ]
        );
        assert_eq!(
            names(
                "vertex_",
                &["x", "r", "g", "b", "a", "n_x", "n_y", "n_z", "k_1"]
            ),
            vec![
                ("vertex_color".into(), vec![1, 2, 3, 4]),
                ("vertex_n".into(), vec![5, 6, 7]),
                ("vertex_k".into(), vec![8]),
            ]
        );
    }

    #[test]
    fn what_mitsuba_ignores_is_no_attribute() {
        // No postfix, a long postfix, a run of two, a run out of order, a prefix seen twice,
        // a run that starts mid-way.
        assert!(names("face_", &["weight", "a_xy", "t_x", "t_y"]).is_empty());
        assert!(names("face_", &["c_0", "c_2", "c_1"]).is_empty());
        assert_eq!(
            names("face_", &["w_0", "q_1", "w_0"]),
            vec![("face_w".into(), vec![0]), ("face_q".into(), vec![1])]
        );
        assert!(names("face_", &["c_y", "c_z"]).is_empty());
        assert!(names("vertex_", &["texture_u", "texture_v"]).is_empty());
    }
}
