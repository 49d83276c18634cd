//! `shell`: the file operations LAMMPS and LIGGGHTS run themselves (their
//! `Shell`/`Input::shell`: `mkdir DIR...`, `rm FILE...`, `rmdir DIR...`,
//! `mv OLD NEW`), which decks use to make their output folders (`shell
//! mkdir post`). demx runs them without a shell; anything else, which the
//! engines would hand to the system's shell (and `cd`, which would move
//! every later file), stops with exit 3 naming it. Like the engines, a
//! failed operation (an existing folder, a missing file) is not an error.
//! `demx check` and a checkpoint's replay do nothing.

use super::Session;
use crate::error::{Error, Result};
use crate::script::Command;
use std::path::Path;

/// Run a `shell` command.
pub fn execute(s: &mut Session, cmd: &Command) -> Result<()> {
    let w = &cmd.words;
    let op = w.get(1).ok_or_else(|| Error::deck(w[0].span, "shell: missing the command to run (mkdir, rm, rmdir, mv)"))?;
    let args = &w[2..];
    let at_least_one = |what: &str| -> Result<()> {
        if args.is_empty() {
            return Err(Error::deck(op.span, format!("shell {}: name at least one {what}", op.text)));
        }
        Ok(())
    };
    // each name a plain path; an option other than the ones below would be
    // a directory or file name to the engine, which no deck means
    for a in args {
        if a.text.starts_with('-') && !matches!((op.text.as_str(), a.text.as_str()), ("mkdir", "-p") | ("rm", "-f")) {
            return Err(Error::unsupported(a.span, format!("shell {} option '{}'", op.text, a.text)).with_hint("demx runs mkdir -p and rm -f only"));
        }
    }
    let paths = || args.iter().filter(|a| !a.text.starts_with('-')).map(|a| Path::new(&a.text));
    let act = !(s.check || s.sim.dry || s.replaying);
    match op.text.as_str() {
        "mkdir" => {
            at_least_one("folder")?;
            // `mkdir -p a/b`: the engines' mkdir takes no options (it would
            // make a folder named "-p"); every deck that writes it means the shell's
            let parents = args.iter().any(|a| a.text == "-p");
            if act {
                for p in paths() {
                    let _ = if parents { std::fs::create_dir_all(p) } else { std::fs::create_dir(p) };
                }
            }
        }
        "rm" => {
            at_least_one("file")?;
            if act {
                for p in paths() {
                    // unlink: a folder is left alone, as by the engines
                    if !p.is_dir() {
                        let _ = std::fs::remove_file(p);
                    }
                }
            }
        }
        "rmdir" => {
            at_least_one("folder")?;
            if act {
                for p in paths() {
                    let _ = std::fs::remove_dir(p);
                }
            }
        }
        "mv" => {
            if args.len() != 2 {
                return Err(Error::deck(op.span, "shell mv: expected 'shell mv OLD NEW'"));
            }
            if act {
                let _ = std::fs::rename(&args[0].text, &args[1].text);
            }
        }
        "cd" => return Err(Error::unsupported(op.span, "shell cd").with_hint("it would move where every later file is read and written")),
        other => {
            return Err(Error::unsupported(op.span, format!("shell {other}"))
                .with_hint("demx runs no system commands; of `shell` it runs mkdir, rm, rmdir and mv itself"))
        }
    }
    s.notes.push((cmd.span, format!("shell {}: run by demx itself, no system shell", op.text)));
    Ok(())
}
