//! Parsing `fix ID group heat/gran initial_temperature T0 [contact_area
//! overlap|projection|constant A] [area_correction no]` (LIGGGHTS 3.8; the
//! same for `heat/gran/conduction`) into an [`crate::engine::heat::HeatGran`].

use super::args::{parse_f64, Args};
use super::Session;
use crate::engine::heat::{ContactArea, HeatGran};
use crate::engine::sim::Dialect;
use crate::error::{Error, Result};
use crate::script::{Command, Word};

/// Parse the fix and add it to the session.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    s.set_dialect(Dialect::Liggghts);
    let name = style.text.as_str();
    a.choice("keyword", &["initial_temperature"])?;
    let w = a.word("T0")?;
    // the engine hands T0 on as printf's "%f" text (fix_heat_gran.cpp,
    // post_create), so it keeps six decimals
    let t0: f64 =
        format!("{:.6}", parse_f64(w)?).parse().map_err(|_| Error::deck(w.span, format!("fix {name}: initial_temperature must be finite")))?;
    let mut area = ContactArea::Overlap;
    while a.more() {
        // LIGGGHTS reads keywords until the first word it does not know and
        // ignores that word and all after it (fix_heat_gran_conduction.cpp:
        // its loop ends when no keyword matched; checked with LIGGGHTS 3.8:
        // `initial_temperature 300. 400. area_correction yes` runs at 300 K
        // without the correction)
        if a.peek().is_some_and(|w| !["contact_area", "area_correction"].contains(&w.text.as_str())) {
            let rest: Vec<String> = a.rest().iter().map(|w| w.text.clone()).collect();
            a.pos += rest.len();
            s.notes.push((
                cmd.span,
                format!("fix {name}: '{}' ignored, as LIGGGHTS 3.8 ignores the words after the last keyword it reads", rest.join(" ")),
            ));
            break;
        }
        let k = a.choice("keyword", &["contact_area", "area_correction"])?;
        match k.text.as_str() {
            "contact_area" => {
                let m = a.choice("contact_area", &["overlap", "projection", "constant"])?;
                area = match m.text.as_str() {
                    "overlap" => ContactArea::Overlap,
                    "projection" => ContactArea::Projection,
                    _ => {
                        let v = a.f64("contact area")?;
                        if !(v > 0.0) {
                            return Err(a.err_prev(format!("fix {name}: 'contact_area constant' value must be > 0")));
                        }
                        ContactArea::Constant(v)
                    }
                };
            }
            _ => {
                if a.yes_no("area_correction")? {
                    return Err(Error::unsupported(k.span, format!("fix {name} area_correction yes")));
                }
            }
        }
    }
    let ntypes = s.sim.ntypes;
    let per_type = |prop: &str| -> Result<Vec<f64>> {
        match s.props.get(prop) {
            Some((_, v)) if v.len() >= ntypes => Ok(v[..ntypes].to_vec()),
            Some((_, v)) => {
                Err(Error::deck(style.span, format!("fix {name}: property/global {prop} has {} values for {ntypes} atom types", v.len())))
            }
            None => Err(Error::deck(style.span, format!("fix {name} needs the per-type property {prop}"))
                .with_hint(format!("define it first: fix ID all property/global {prop} peratomtype VALUE..."))),
        }
    };
    let conductivity = per_type("thermalConductivity")?;
    if let Some(t) = conductivity.iter().position(|&k| k < 0.0) {
        return Err(Error::deck(style.span, format!("fix {name}: thermal conductivity of type {} must not be < 0", t + 1)));
    }
    let capacity = per_type("thermalCapacity")?;
    if s.sim.fixes.iter().any(|f| f.style().starts_with("heat/gran") && f.id() != id) {
        return Err(Error::deck(style.span, format!("fix {name}: a scene may have only one heat/gran fix")));
    }
    let fix = HeatGran { id: id.to_string(), style: name.to_string(), group, area, conductivity, capacity, t0 };
    fix.columns(&mut s.sim);
    s.add_fix(Box::new(fix))
}
