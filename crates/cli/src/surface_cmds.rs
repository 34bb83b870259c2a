//! The surface commands: healing (`mesh --heal`, `heal`, the hint in
//! `check`) and `convert` for surfaces and tet meshes.
use crate::{write_options, Fail, WriteArgs};
use clap::Args;
use parafront_io::{read_mesh, surface_format, write_mesh, write_surface, SurfaceFormat};
use parafront_surface::heal::{heal, HealOptions, HealReport};
use parafront_surface::read::{read_surface, Format};
use parafront_surface::validate::{validate, Class, Report};
use parafront_surface::Surface;
use std::path::{Path, PathBuf};

/// The healing flags of `mesh`.
#[derive(Args)]
pub struct HealArgs {
    /// Merge the vertices a float rounding split apart where that closes
    /// open edges or removes a pinched vertex (boundary vertices only,
    /// never the two ends of an edge), drop the triangles the merge makes
    /// degenerate or duplicate, and orient each touched shell; every change
    /// is reported. A valid surface is left as it is.
    #[arg(long)]
    pub heal: bool,
    #[command(flatten)]
    pub tol: HealTol,
    /// With --heal, also write the healed surface to this file (.stl, .obj,
    /// .off, .msh, .mesh or .vtu), e.g. for `meshcheck.py --surface`.
    #[arg(long, requires = "heal")]
    pub healed_surface: Option<PathBuf>,
}

/// The merge tolerance.
#[derive(Args)]
pub struct HealTol {
    /// Largest merge distance, as a fraction of the shortest edge at
    /// either vertex [default: 1e-3].
    #[arg(long, value_name = "REL")]
    pub heal_tol: Option<f64>,
}

impl HealTol {
    fn options(&self) -> Result<HealOptions, Fail> {
        let mut o = HealOptions::default();
        if let Some(t) = self.heal_tol {
            if !(t.is_finite() && (0.0..1.0).contains(&t)) {
                return Err(Fail(2, format!("--heal-tol {t}: expected 0 <= REL < 1")));
            }
            o.rel_tol = t;
        }
        Ok(o)
    }
}

/// Heals `s` for `mesh --heal`: prints the report and writes the healed
/// surface when asked, once it validates (the mesher reports it if not).
pub fn heal_for_mesh(s: Surface, a: &HealArgs, w: &WriteArgs) -> Result<Surface, Fail> {
    if !a.heal {
        if a.tol.heal_tol.is_some() {
            return Err(Fail(2, "--heal-tol needs --heal".into()));
        }
        return Ok(s);
    }
    let h = heal(&s, &a.tol.options()?);
    println!("{}", h.report);
    if let Some(p) = &a.healed_surface {
        if validate(&h.surface).is_valid() {
            write_surface(p, &h.surface, &write_options(w, Some(&h.surface))?)?;
            println!("wrote the healed surface to {}", p.display());
        }
    }
    Ok(h.surface)
}

/// `parafront heal IN OUT`: the healed surface alone, written only when it
/// is valid.
pub fn run_heal(input: &Path, output: &Path, tol: &HealTol, w: &WriteArgs) -> Result<(), Fail> {
    if surface_format(output).is_none() {
        return Err(Fail(
            2,
            format!(
                "{}: unknown surface format (use .stl, .obj, .off, .msh, .mesh or .vtu)",
                output.display()
            ),
        ));
    }
    let s = read_surface(input)?;
    let h = heal(&s, &tol.options()?);
    println!("{}: {}", input.display(), h.report);
    let r = validate(&h.surface);
    if !r.is_valid() {
        println!("{}: {r}", input.display());
        return Err(Fail(
            1,
            format!(
                "{}: healing leaves a surface that is not valid for meshing; nothing written",
                input.display()
            ),
        ));
    }
    write_surface(output, &h.surface, &write_options(w, Some(&h.surface))?)?;
    println!(
        "wrote {} ({} points, {} triangles)",
        output.display(),
        h.surface.points.len(),
        h.surface.tris.len()
    );
    Ok(())
}

/// For `check`: when the open edges or pinched vertices close by healing,
/// a note that says so, with the largest distance, and what is left.
pub fn heal_hint(path: &Path, s: &Surface, r: &Report) -> Option<String> {
    let (open, pinched) = (r.count(Class::OpenEdge), r.count(Class::PinchedVertex));
    if open + pinched == 0 {
        return None;
    }
    let h = heal(s, &HealOptions::default());
    if !h.report.changed() {
        return None;
    }
    let after = validate(&h.surface);
    let closed = after.count(Class::OpenEdge) + after.count(Class::PinchedVertex) == 0;
    let HealReport {
        vertices_merged: n,
        max_distance: d,
        max_relative: rel,
        ..
    } = h.report;
    let what = format!(
        "{open} open edge{} and {pinched} pinched vert{}",
        if open == 1 { "" } else { "s" },
        if pinched == 1 { "ex" } else { "ices" }
    );
    let head = format!(
        "note: merging {n} vertices that lie within {d:.3e} of another ({rel:.1e} of the shortest edge there)"
    );
    let cmd = format!(
        "`parafront mesh --heal` (or `parafront heal {} HEALED.stl`)",
        path.display()
    );
    Some(if after.is_valid() {
        format!("{head} closes the {what}; the healed surface is valid: {cmd}")
    } else if closed {
        format!("{head} closes the {what}, but the healed surface is still not valid:\n{after}")
    } else {
        format!(
            "{head} closes some of the {what}; the rest are real:\n{after}\n{cmd} heals what it can"
        )
    })
}

/// `parafront convert IN OUT`: a surface (STL, OBJ, OFF, or a .msh/.mesh
/// without tets) to any surface format, a tet mesh to .vtu/.msh/.mesh, or
/// a tet mesh's boundary triangles to STL/OBJ/OFF.
pub fn run_convert(input: &Path, output: &Path, w: &WriteArgs) -> Result<(), Fail> {
    let unknown = || {
        Fail(
            2,
            format!(
                "{}: unknown format (use .stl, .obj, .off, .msh, .mesh or .vtu)",
                output.display()
            ),
        )
    };
    let out_fmt = surface_format(output).ok_or_else(unknown)?;
    let in_surface = matches!(
        Format::from_path(input),
        Some(Format::Stl | Format::Obj | Format::Off)
    );
    let s = if in_surface {
        read_surface(input)?
    } else {
        let m = read_mesh(input)?;
        if m.tets.is_empty() && !input_is_vtu(input) {
            // Read as a surface again to keep the patch names.
            read_surface(input)?
        } else if let SurfaceFormat::Mesh(_) = out_fmt {
            write_mesh(output, &m, &write_options(w, None)?)?;
            println!(
                "{} -> {}: {} points, {} tets, {} boundary triangles",
                input.display(),
                output.display(),
                m.points.len(),
                m.tets.len(),
                m.bnd_tris.len()
            );
            return Ok(());
        } else {
            boundary_surface(&m)
        }
    };
    write_surface(output, &s, &write_options(w, Some(&s))?)?;
    let mut tags = s.patch.clone();
    tags.sort_unstable();
    tags.dedup();
    println!(
        "{} -> {}: {} points, {} triangles, {} patch{}",
        input.display(),
        output.display(),
        s.points.len(),
        s.tris.len(),
        tags.len(),
        if tags.len() == 1 { "" } else { "es" }
    );
    Ok(())
}

fn input_is_vtu(p: &Path) -> bool {
    parafront_io::Format::from_path(p) == Some(parafront_io::Format::Vtu)
}

/// The boundary triangles of a tet mesh as a surface of the points they use.
fn boundary_surface(m: &parafront_mesh::TetMesh) -> Surface {
    let mut id = vec![u32::MAX; m.points.len()];
    let mut s = Surface::default();
    for t in &m.bnd_tris {
        let t = t.map(|p| {
            let i = &mut id[p.idx()];
            if *i == u32::MAX {
                *i = s.points.len() as u32;
                s.points.push(m.points[p.idx()]);
            }
            *i
        });
        s.tris.push(t);
    }
    s.patch = m.bnd_patch.clone();
    s
}
