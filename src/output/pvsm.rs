//! A ParaView state file (`.pvsm`, ParaView 5.11's XML server-manager state) that opens a run's
//! volume series and joint series as a user would set them up by hand: the volume without the
//! blocks asked to be hidden (a `Threshold` on the frames' cell field `block_id`, inverted),
//! warped by `displacement` times a scale factor and coloured by |displacement|, and every joint
//! surface coloured by `opening`, all on one time axis (the animation snaps to the frames' times).
//!
//! Only the proxies the state needs are written (readers, filters, representations, lookup
//! tables, one render view, the time keeper and the animation scene); ParaView gives every
//! property not written its default when it loads the state. Paths are written absolute (ParaView
//! resolves a relative path against its working directory, not the state file's). Colour ranges
//! are fixed (`[0, max]`, not rescaled per frame) so a colour means the same value at every time.
//! Checked by loading it in ParaView itself (`scripts/render_pvsm.py`, `make test`).

use crate::error::OutputError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What the state shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PvsmScene {
    /// The volume series (`<scene>.pvd`).
    pub volume: PathBuf,
    /// `block_id`s of the volume to hide (the rock under a dam); empty: show every block.
    pub hide_blocks: Vec<i32>,
    /// Factor on the displacement of the warp [-] (1: true scale).
    pub warp_scale: f64,
    /// Upper end of the |displacement| colour range [m] (> 0).
    pub displacement_max: f64,
    /// The joint series (`joints/<joint>.pvd`).
    pub joints: Vec<PathBuf>,
    /// Upper end of the opening colour range [m] (> 0).
    pub opening_max: f64,
    /// The view's camera; `None`: ParaView's default (looking down −z), reset to the data.
    pub camera: Option<Camera>,
}

/// A camera: where it is, what it looks at, which way is up [m, m, -].
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: [f64; 3],
    pub focal_point: [f64; 3],
    pub view_up: [f64; 3],
}

/// Diverging blue–white–red (ParaView's "Cool to Warm") for |u|, and viridis for the opening,
/// as (position in [0, 1], r, g, b).
const COOL_TO_WARM: [[f64; 4]; 3] = [[0.0, 0.231373, 0.298039, 0.752941], [0.5, 0.865003, 0.865003, 0.865003], [1.0, 0.705882, 0.0156863, 0.14902]];
const VIRIDIS: [[f64; 4]; 3] = [[0.0, 0.267004, 0.004874, 0.329415], [0.5, 0.128729, 0.563265, 0.551229], [1.0, 0.993248, 0.906157, 0.143936]];

/// Ids of the fixed proxies (readers and their representations count up from 100).
const VIEW: u32 = 10;
const TIME_KEEPER: u32 = 11;
const ANIMATION: u32 = 12;
const LUT_U: u32 = 20;
const LUT_OPENING: u32 = 21;

enum Value<'a> {
    Elements(Vec<String>),
    Proxies(&'a [(u32, Option<u32>)]),
}

fn property(x: &mut String, id: u32, name: &str, v: Value) {
    let n = match &v {
        Value::Elements(e) => e.len(),
        Value::Proxies(p) => p.len(),
    };
    let _ = write!(x, "      <Property name=\"{name}\" id=\"{id}.{name}\" number_of_elements=\"{n}\">");
    match v {
        Value::Elements(e) => {
            for (i, s) in e.iter().enumerate() {
                let _ = write!(x, "<Element index=\"{i}\" value=\"{}\"/>", xml_escape(s));
            }
        }
        Value::Proxies(p) => {
            for (id, port) in p {
                match port {
                    Some(k) => {
                        let _ = write!(x, "<Proxy value=\"{id}\" output_port=\"{k}\"/>");
                    }
                    None => {
                        let _ = write!(x, "<Proxy value=\"{id}\"/>");
                    }
                }
            }
        }
    }
    x.push_str("</Property>\n");
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;").replace('>', "&gt;")
}

fn elements<T: ToString>(v: &[T]) -> Value<'static> {
    Value::Elements(v.iter().map(|x| x.to_string()).collect())
}

/// One proxy with its properties.
fn proxy(x: &mut String, group: &str, kind: &str, id: u32, props: impl FnOnce(&mut String)) {
    let _ = writeln!(x, "    <Proxy group=\"{group}\" type=\"{kind}\" id=\"{id}\" servers=\"21\">");
    props(x);
    x.push_str("    </Proxy>\n");
}

/// A lookup table over [0, `max`] with `stops` (positions in [0, 1]).
fn lookup_table(x: &mut String, id: u32, max: f64, stops: &[[f64; 4]]) {
    proxy(x, "lookup_tables", "PVLookupTable", id, |x| {
        let pts: Vec<String> = stops.iter().flat_map(|s| [format!("{:e}", s[0] * max), s[1].to_string(), s[2].to_string(), s[3].to_string()]).collect();
        property(x, id, "RGBPoints", Value::Elements(pts));
        property(x, id, "ColorSpace", elements(&[if stops == COOL_TO_WARM.as_slice() { 3 } else { 2 }]));
        property(x, id, "VectorMode", elements(&[0]));
        property(x, id, "ScalarRangeInitialized", elements(&[1]));
        // never rescaled: a colour is the same value at every frame
        property(x, id, "AutomaticRescaleRangeMode", elements(&[-1]));
    });
}

/// A surface representation of output 0 of `input` coloured by point array `array` with `lut`.
fn representation(x: &mut String, id: u32, input: u32, array: &str, lut: u32) {
    proxy(x, "representations", "UnstructuredGridRepresentation", id, |x| {
        property(x, id, "Input", Value::Proxies(&[(input, Some(0))]));
        property(x, id, "Representation", elements(&["Surface"]));
        property(x, id, "ColorArrayName", elements(&["", "", "", "0", array]));
        property(x, id, "LookupTable", Value::Proxies(&[(lut, None)]));
        property(x, id, "Visibility", elements(&[1]));
    });
}

fn absolute(p: &Path) -> Result<String, OutputError> {
    let a = std::path::absolute(p).map_err(|e| OutputError::write(p, format!("cannot make the path absolute for the ParaView state: {e}")))?;
    Ok(a.to_string_lossy().into_owned())
}

/// The state's XML.
pub fn pvsm_xml(s: &PvsmScene) -> Result<String, OutputError> {
    for (what, v) in [("warp_scale", s.warp_scale), ("displacement_max", s.displacement_max), ("opening_max", s.opening_max)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(OutputError::write(&s.volume, format!("ParaView state: {what} = {v} must be finite and > 0")));
        }
    }
    let mut x = String::from("<?xml version=\"1.0\"?>\n<ParaView>\n  <ServerManagerState version=\"5.11.0\">\n");
    // (id, name) of the pipeline objects, in the order ParaView lists them
    let mut sources: Vec<(u32, String)> = Vec::new();
    let mut reps: Vec<u32> = Vec::new();
    lookup_table(&mut x, LUT_U, s.displacement_max, &COOL_TO_WARM);
    lookup_table(&mut x, LUT_OPENING, s.opening_max, &VIRIDIS);
    let (reader, threshold, warp, rep) = (100, 101, 102, 103);
    let volume = absolute(&s.volume)?;
    proxy(&mut x, "sources", "PVDReader", reader, |x| property(x, reader, "FileName", Value::Elements(vec![volume.clone()])));
    sources.push((reader, s.volume.file_name().map_or("volume".into(), |n| n.to_string_lossy().into_owned())));
    let mut last = reader;
    if let (Some(lo), Some(hi)) = (s.hide_blocks.iter().min(), s.hide_blocks.iter().max()) {
        // hidden blocks must be one contiguous range of ids: the threshold keeps what is outside
        proxy(&mut x, "filters", "Threshold", threshold, |x| {
            property(x, threshold, "Input", Value::Proxies(&[(reader, Some(0))]));
            property(x, threshold, "SelectInputScalars", elements(&["0", "0", "0", "1", "block_id"]));
            property(x, threshold, "LowerThreshold", elements(&[*lo]));
            property(x, threshold, "UpperThreshold", elements(&[*hi]));
            property(x, threshold, "ThresholdMethod", elements(&[0]));
            property(x, threshold, "Invert", elements(&[1]));
        });
        sources.push((threshold, format!("without block_id {lo}..{hi}")));
        last = threshold;
    }
    proxy(&mut x, "filters", "WarpVector", warp, |x| {
        property(x, warp, "Input", Value::Proxies(&[(last, Some(0))]));
        property(x, warp, "SelectInputVectors", elements(&["0", "0", "0", "0", "displacement"]));
        property(x, warp, "ScaleFactor", elements(&[s.warp_scale]));
    });
    sources.push((warp, format!("warped by displacement x {}", s.warp_scale)));
    representation(&mut x, rep, warp, "displacement", LUT_U);
    reps.push(rep);
    for (k, j) in s.joints.iter().enumerate() {
        let (id, rid) = (200 + 2 * k as u32, 201 + 2 * k as u32);
        let file = absolute(j)?;
        proxy(&mut x, "sources", "PVDReader", id, |x| property(x, id, "FileName", Value::Elements(vec![file.clone()])));
        representation(&mut x, rid, id, "opening", LUT_OPENING);
        sources.push((id, j.file_name().map_or(format!("joint {k}"), |n| n.to_string_lossy().into_owned())));
        reps.push(rid);
    }
    let rep_refs: Vec<(u32, Option<u32>)> = reps.iter().map(|&r| (r, None)).collect();
    proxy(&mut x, "views", "RenderView", VIEW, |x| {
        property(x, VIEW, "Representations", Value::Proxies(&rep_refs));
        property(x, VIEW, "OrientationAxesVisibility", elements(&[1]));
        if let Some(c) = &s.camera {
            property(x, VIEW, "CameraPosition", elements(&c.position));
            property(x, VIEW, "CameraFocalPoint", elements(&c.focal_point));
            property(x, VIEW, "CameraViewUp", elements(&c.view_up));
            property(x, VIEW, "CenterOfRotation", elements(&c.focal_point));
        }
    });
    let src_refs: Vec<(u32, Option<u32>)> = sources.iter().map(|s| (s.0, None)).collect();
    proxy(&mut x, "misc", "TimeKeeper", TIME_KEEPER, |x| {
        property(x, TIME_KEEPER, "TimeSources", Value::Proxies(&src_refs));
        property(x, TIME_KEEPER, "Views", Value::Proxies(&[(VIEW, None)]));
    });
    proxy(&mut x, "animation", "AnimationScene", ANIMATION, |x| {
        property(x, ANIMATION, "TimeKeeper", Value::Proxies(&[(TIME_KEEPER, None)]));
        property(x, ANIMATION, "ViewModules", Value::Proxies(&[(VIEW, None)]));
        // snap to the frames' times
        property(x, ANIMATION, "PlayMode", elements(&[2]));
    });
    let collection = |x: &mut String, name: &str, items: &[(u32, String)]| {
        let _ = writeln!(x, "    <ProxyCollection name=\"{name}\">");
        for (id, n) in items {
            let _ = writeln!(x, "      <Item id=\"{id}\" name=\"{}\"/>", xml_escape(n));
        }
        x.push_str("    </ProxyCollection>\n");
    };
    collection(&mut x, "sources", &sources);
    collection(&mut x, "representations", &reps.iter().map(|&r| (r, format!("Representation{r}"))).collect::<Vec<_>>());
    collection(&mut x, "lookup_tables", &[(LUT_U, "displacement.PVLookupTable".into()), (LUT_OPENING, "opening.PVLookupTable".into())]);
    collection(&mut x, "views", &[(VIEW, "RenderView1".into())]);
    collection(&mut x, "timekeeper", &[(TIME_KEEPER, "TimeKeeper1".into())]);
    collection(&mut x, "animation", &[(ANIMATION, "AnimationScene1".into())]);
    x.push_str("  </ServerManagerState>\n</ParaView>\n");
    Ok(x)
}

/// Write the state to `path` (whole: temp file and rename).
pub fn write_pvsm(path: &Path, s: &PvsmScene) -> Result<(), OutputError> {
    let x = pvsm_xml(s)?;
    crate::files::write_whole(path, x.as_bytes()).map_err(|(p, m)| OutputError::write(p, m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_state_hides_the_blocks_warps_and_colours_and_lists_every_joint() {
        let s = PvsmScene {
            volume: "/r/dam.pvd".into(),
            hide_blocks: vec![1],
            warp_scale: 200.0,
            displacement_max: 0.05,
            joints: vec!["/r/joints/J01.pvd".into(), "/r/joints/J02.pvd".into()],
            opening_max: 0.01,
            camera: Some(Camera { position: [0.0, 900.0, 300.0], focal_point: [0.0, 0.0, 100.0], view_up: [0.0, 0.0, 1.0] }),
        };
        let x = pvsm_xml(&s).unwrap();
        for want in ["type=\"Threshold\"", "value=\"block_id\"", "name=\"Invert\"", "type=\"WarpVector\"", "value=\"200\"", "value=\"displacement\"", "value=\"opening\"", "/r/joints/J02.pvd", "name=\"TimeSources\" id=\"11.TimeSources\" number_of_elements=\"5\"", "name=\"CameraPosition\" id=\"10.CameraPosition\" number_of_elements=\"3\"><Element index=\"0\" value=\"0\"/><Element index=\"1\" value=\"900\"/>"] {
            assert!(x.contains(want), "{want} missing:\n{x}");
        }
        // every proxy referenced is defined
        for id in x.split("<Proxy value=\"").skip(1).map(|s| s.split('"').next().unwrap()) {
            assert!(x.contains(&format!("id=\"{id}\" servers")), "proxy {id} referenced but not defined");
        }
        // nothing hidden: no threshold, the warp reads the reader
        let x = pvsm_xml(&PvsmScene { hide_blocks: vec![], ..s.clone() }).unwrap();
        assert!(!x.contains("Threshold") && x.contains("<Proxy value=\"100\" output_port=\"0\"/>"));
        assert!(pvsm_xml(&PvsmScene { opening_max: 0.0, ..s }).unwrap_err().to_string().contains("opening_max"));
    }
}
