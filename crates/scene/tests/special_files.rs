//! Special files where a scene expects a regular one: a FIFO as the scene, a mesh or an
//! environment map must be an error at once (opening one used to block forever), checked on a
//! thread with a time limit. FIFOs cannot be checked in, so they are made here with `mkfifo`.

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

fn load_within(path: &Path, limit: Duration) -> Result<String, String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        let r = restir_scene::load_scene(&p, &restir_scene::LoadOptions::default());
        let _ = tx.send(r.map(|_| ()).map_err(|e| e.to_string()));
    });
    match rx.recv_timeout(limit) {
        Ok(Ok(())) => Err("loaded".into()),
        Ok(Err(e)) => Ok(e),
        Err(_) => Err(format!("no answer within {limit:?} (blocked on the FIFO?)")),
    }
}

#[test]
fn fifos_are_refused_without_blocking() {
    let dir = restir_testkit::TempDir::new("fifo", "refused");
    let fifo = |name: &str| {
        let p = dir.join(name);
        let ok = std::process::Command::new("mkfifo")
            .arg(&p)
            .status()
            .expect("mkfifo runs")
            .success();
        assert!(ok, "mkfifo {}", p.display());
        p
    };
    let head = r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;
    fifo("mesh.obj");
    fifo("sky.exr");
    let cases = [
        (
            "mesh.xml",
            r#"<shape type="obj"><string name="filename" value="mesh.obj"/></shape>"#,
            "cannot read mesh",
        ),
        (
            "sky.xml",
            r#"<emitter type="envmap"><string name="filename" value="sky.exr"/></emitter>"#,
            "envmap: cannot read image",
        ),
    ];
    for (name, body, want) in cases {
        let scene = dir.join(name);
        std::fs::write(&scene, format!("{head}{body}</scene>")).unwrap();
        let e = load_within(&scene, Duration::from_secs(10)).unwrap();
        assert!(e.contains(want) && e.contains("not a regular file"), "{e}");
    }
    let scene = fifo("scene.xml");
    let e = load_within(&scene, Duration::from_secs(10)).unwrap();
    assert!(
        e.contains("cannot read scene: it is not a regular file"),
        "{e}"
    );
}
