//! Helpers shared by the binary's test files.
#![allow(dead_code)] // each test file uses its own share

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// This test binary's scratch directory.
static SCRATCH: OnceLock<PathBuf> = OnceLock::new();

/// `name` in this test binary's scratch directory (made on first use, the
/// same for every test of the binary), which is removed with everything
/// the tests wrote there when the binary exits, passed or failed.
pub fn tmp(name: &str) -> PathBuf {
    SCRATCH
        .get_or_init(|| {
            let bin = std::env::current_exe()
                .ok()
                .and_then(|e| e.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .unwrap_or_default();
            let d = std::env::temp_dir().join(format!("parafront-{bin}-{}", std::process::id()));
            std::fs::create_dir_all(&d).unwrap();
            #[cfg(unix)]
            // SAFETY: registers a plain function with no arguments; the
            // test harness's exit (a return from main, or `exit(101)` when
            // a test failed) runs it.
            unsafe {
                libc::atexit(remove_scratch);
            }
            d
        })
        .join(name)
}

#[cfg(unix)]
extern "C" fn remove_scratch() {
    if let Some(d) = SCRATCH.get() {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// Whether python3 with numpy and meshio is there.
pub fn have_meshio() -> bool {
    Command::new("python3")
        .args(["-c", "import numpy, meshio"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false)
}

/// `../shared/tools/meshcheck.py --surface` passes on `vol`, when the tool
/// and python3 with numpy and meshio are there.
pub fn meshcheck(vol: &Path, surf: &Path) {
    let tool = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/tools/meshcheck.py");
    if !tool.exists() || !have_meshio() {
        eprintln!("meshcheck skipped: meshcheck.py or python3 with numpy+meshio not available");
        return;
    }
    let o = Command::new("python3")
        .arg(&tool)
        .arg(vol)
        .arg("--surface")
        .arg(surf)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
}

/// The tet count of a run's summary ("N tets, M points, K region(s)").
pub fn tets_said(out: &str) -> usize {
    out.lines()
        .find_map(|l| l.strip_suffix(" region").or(l.strip_suffix(" regions")))
        .and_then(|l| l.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no tet count in\n{out}"))
}
