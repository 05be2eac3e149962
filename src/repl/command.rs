//! REPL input → [`Input`]: a `:command` with its arguments, or mprog code to add to the
//! session's program. The command table ([`COMMANDS`]) is the single list that parsing,
//! `:help` and completion read.

use std::path::PathBuf;

/// One REPL command (without the leading `:`).
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `:load prog.mprog`: replace the session's program with a file.
    Load(PathBuf),
    /// `:motion file`: make a motion file (bvh, npy, json) the current motion, and the take
    /// `:run` edits.
    Motion(PathBuf),
    /// `:gen "prompt" [seconds] [seed]`: generate the current motion with the model.
    Gen {
        /// Text prompt.
        prompt: String,
        /// Length in seconds.
        seconds: f32,
        /// Noise seed.
        seed: u64,
    },
    /// `:run [SOLVER] [SEED] [name=value …]`: solve the session's program with the model.
    Run {
        /// Solver name (`guide` by default).
        solver: String,
        /// Noise seed.
        seed: u64,
        /// Solver knobs.
        knobs: Vec<(String, f64)>,
    },
    /// `:eval <expr or statement>`: its value or error per frame of the current motion.
    Eval(String),
    /// `:grad <statement>`: gradient magnitude per joint.
    Grad(String),
    /// `:score`: the program's per-statement errors on the current motion.
    Score,
    /// `:render out.gif|png`: a picture of the current motion (any output kind).
    Render(PathBuf),
    /// `:view out.html`: the 3-D viewer page of the current motion (any output kind).
    View(PathBuf),
    /// `:save FILE`: the program (`.mprog`) or the current motion, as any kind of the
    /// output table ([`crate::formats::outputs::OUTPUT_KINDS`]).
    Save(PathBuf),
    /// `:rig [RIG [MAP.toml] | -]`: save `.bvh` / `.glb` motions on this rig (a `.bvh` or a
    /// skinned `.glb`, with a mapping file for joint names mprog does not know; `-`: on the
    /// 22-joint skeleton again; no argument: say which).
    Rig(Option<(PathBuf, Option<PathBuf>)>),
    /// `:show`: print the session's program.
    Show,
    /// `:drop N` or `:drop N-M`: delete lines of the session's program (1-based, inclusive).
    Drop {
        /// First line.
        first: usize,
        /// Last line.
        last: usize,
    },
    /// `:clear`: empty the session's program.
    Clear,
    /// `:help [command]`.
    Help(Option<String>),
    /// `:quit`.
    Quit,
}

/// What the user typed.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// Nothing but blanks or comments.
    Empty,
    /// A command.
    Command(Command),
    /// mprog code for the session's program.
    Code(String),
}

/// One entry of the command table.
#[derive(Clone, Copy, Debug)]
pub struct CommandDoc {
    /// Name without `:`.
    pub name: &'static str,
    /// Short forms.
    pub aliases: &'static [&'static str],
    /// Argument synopsis.
    pub args: &'static str,
    /// One line of help.
    pub help: &'static str,
}

/// Every command, in `:help` order.
pub const COMMANDS: &[CommandDoc] = &[
    doc(
        "load",
        &["l"],
        "FILE.mprog",
        "replace the session's program with a file",
    ),
    doc(
        "motion",
        &["m"],
        "FILE",
        "load the current motion (.bvh, .npy, .json); `:run` then edits it",
    ),
    doc(
        "gen",
        &[],
        "\"PROMPT\" [SECONDS] [SEED]",
        "generate the current motion with the model (default 6 s, seed 1)",
    ),
    doc(
        "run",
        &[],
        "[SOLVER] [SEED] [KNOB=VALUE …] [strength=S]",
        "solve the session's program with the model (`:help run` lists the solvers and their knobs; default guide, seed 1); after `:motion FILE` it edits that take (`strength=S`, 0 keeps it, 1 ignores it); the result becomes the current motion",
    ),
    doc(
        "eval",
        &["e"],
        "EXPR | STATEMENT",
        "value (or error) per frame of the current motion: min/mean/max and a sparkline",
    ),
    doc(
        "grad",
        &["g"],
        "STATEMENT",
        "gradient magnitude of a statement's error per joint, top joints first",
    ),
    doc(
        "score",
        &["s"],
        "",
        "the program's error per statement on the current motion",
    ),
    doc(
        "render",
        &["r"],
        "OUT.gif | OUT.png",
        "draw the current motion",
    ),
    doc(
        "view",
        &["v"],
        "OUT.html",
        "write the 3-D viewer page of the current motion, with the program's geometry and error timeline",
    ),
    doc(
        "save",
        &["w"],
        "FILE.mprog | OUT",
        "write the session's program, or the current motion as any output kind (listed below; with the program, scores and geometry in its meta)",
    ),
    doc(
        "rig",
        &[],
        "[RIG [MAP.toml] | -]",
        "save .bvh and .glb motions on your character's rig (a .bvh of its skeleton, Mixamo or any rig mprog reads, or a skinned .glb, whose .glb outputs are that file animated; MAP.toml names joints mprog does not recognise, as --rig-map does); `-` goes back to the 22-joint skeleton",
    ),
    doc(
        "show",
        &["p"],
        "",
        "print the session's program with line numbers",
    ),
    doc(
        "drop",
        &["d"],
        "LINE | FIRST-LAST",
        "delete lines of the session's program (numbers as `:show` prints them)",
    ),
    doc("clear", &[], "", "empty the session's program"),
    doc(
        "help",
        &["h", "?"],
        "[COMMAND]",
        "this list, or one command's help",
    ),
    doc("quit", &["q", "exit"], "", "leave (Ctrl-D works too)"),
];

const fn doc(
    name: &'static str,
    aliases: &'static [&'static str],
    args: &'static str,
    help: &'static str,
) -> CommandDoc {
    CommandDoc {
        name,
        aliases,
        args,
        help,
    }
}

/// The command table entry for a name or alias.
pub fn find(name: &str) -> Option<&'static CommandDoc> {
    COMMANDS
        .iter()
        .find(|c| c.name == name || c.aliases.contains(&name))
}

/// Parses one (possibly multi-line) input.
pub fn parse(text: &str) -> Result<Input, String> {
    let trimmed = text.trim();
    let Some(rest) = trimmed.strip_prefix(':') else {
        let code_lines = trimmed
            .lines()
            .any(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        return Ok(if code_lines {
            Input::Code(trimmed.to_string())
        } else {
            Input::Empty
        });
    };
    let (name, args) = match rest.find(char::is_whitespace) {
        Some(i) => (&rest[..i], rest[i..].trim()),
        None => (rest, ""),
    };
    let Some(cmd) = find(name) else {
        return Err(format!("unknown command `:{name}`; `:help` lists them"));
    };
    parse_args(cmd, args).map(Input::Command)
}

fn parse_args(cmd: &CommandDoc, args: &str) -> Result<Command, String> {
    let usage = || format!("usage: :{} {}", cmd.name, cmd.args);
    let need = |what: &str| -> Result<String, String> {
        if args.is_empty() {
            Err(format!("`:{}` needs {what}; {}", cmd.name, usage()))
        } else {
            Ok(args.to_string())
        }
    };
    let none = |c: Command| -> Result<Command, String> {
        if args.is_empty() {
            Ok(c)
        } else {
            Err(format!("`:{}` takes no argument; {}", cmd.name, usage()))
        }
    };
    match cmd.name {
        "load" => need("a program file").map(|a| Command::Load(unquote(&a).into())),
        "motion" => need("a motion file").map(|a| Command::Motion(unquote(&a).into())),
        "render" => need("an output file").map(|a| Command::Render(unquote(&a).into())),
        "view" => need("an output .html file").map(|a| Command::View(unquote(&a).into())),
        "save" => need("a file").map(|a| Command::Save(unquote(&a).into())),
        "rig" => match words(args)?.as_slice() {
            [] => Ok(Command::Rig(None)),
            [rig] => Ok(Command::Rig(Some((rig.into(), None)))),
            [rig, map] => Ok(Command::Rig(Some((rig.into(), Some(map.into()))))),
            _ => Err(format!(
                "`:rig` takes a rig file and optionally its mapping file; {}",
                usage()
            )),
        },
        "eval" => need("an expression or a statement").map(Command::Eval),
        "grad" => need("a statement").map(Command::Grad),
        "gen" => parse_gen(args).map_err(|e| format!("{e}; {}", usage())),
        "run" => parse_run(args).map_err(|e| format!("{e}; {}", usage())),
        "drop" => parse_drop(&need("a line number")?).map_err(|e| format!("{e}; {}", usage())),
        "score" => none(Command::Score),
        "show" => none(Command::Show),
        "clear" => none(Command::Clear),
        "quit" => none(Command::Quit),
        "help" => Ok(Command::Help(
            (!args.is_empty()).then(|| args.trim_start_matches(':').to_string()),
        )),
        other => unreachable!("command `{other}` is in the table but not parsed"),
    }
}

/// A path argument with optional surrounding quotes.
/// Words of `s`, each bare or in double quotes (for paths with spaces).
fn words(s: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut rest = s.trim_start();
    while !rest.is_empty() {
        if let Some(quoted) = rest.strip_prefix('"') {
            let end = quoted
                .find('"')
                .ok_or("a quote is not closed; write \"my rig.bvh\"")?;
            out.push(quoted[..end].to_string());
            rest = quoted[end + 1..].trim_start();
        } else {
            let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
            out.push(rest[..end].to_string());
            rest = rest[end..].trim_start();
        }
    }
    Ok(out)
}

fn unquote(s: &str) -> String {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|r| r.strip_suffix('"'))
        .unwrap_or(s)
        .to_string()
}

fn parse_run(args: &str) -> Result<Command, String> {
    let (mut solver, mut seed, mut knobs) = ("guide".to_string(), 1, Vec::new());
    for (i, w) in args.split_whitespace().enumerate() {
        if let Some((k, v)) = w.split_once('=') {
            let v: f64 = v.parse().map_err(|_| format!("`{v}` is not a number"))?;
            knobs.push((k.to_string(), v));
        } else if let Ok(n) = w.parse::<u64>() {
            seed = n;
        } else if i == 0 {
            solver = w.to_string();
        } else {
            return Err(format!("unexpected `{w}`"));
        }
    }
    Ok(Command::Run {
        solver,
        seed,
        knobs,
    })
}

fn parse_drop(args: &str) -> Result<Command, String> {
    let line = |w: &str| -> Result<usize, String> {
        w.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| n >= 1)
            .ok_or_else(|| format!("`{}` is not a line number (1, 2, …)", w.trim()))
    };
    let (first, last) = match args.split_once('-') {
        Some((a, b)) => (line(a)?, line(b)?),
        None => {
            let n = line(args)?;
            (n, n)
        }
    };
    if last < first {
        return Err(format!("the range {first}-{last} runs backwards"));
    }
    Ok(Command::Drop { first, last })
}

fn parse_gen(args: &str) -> Result<Command, String> {
    let args = args.trim();
    let Some(rest) = args.strip_prefix('"') else {
        return Err("the prompt goes in double quotes".into());
    };
    let Some(end) = rest.find('"') else {
        return Err("the prompt's closing quote is missing".into());
    };
    let prompt = rest[..end].trim().to_string();
    if prompt.is_empty() {
        return Err("the prompt is empty".into());
    }
    let mut words = rest[end + 1..].split_whitespace();
    let seconds = match words.next() {
        None => 6.0,
        Some(w) => {
            let w = w.strip_suffix('s').unwrap_or(w);
            w.parse::<f32>()
                .ok()
                .filter(|s| s.is_finite() && *s > 0.0)
                .ok_or_else(|| format!("`{w}` is not a length in seconds"))?
        }
    };
    let seed = match words.next() {
        None => 1,
        Some(w) => w
            .parse::<u64>()
            .map_err(|_| format!("`{w}` is not a seed (a whole number)"))?,
    };
    if let Some(extra) = words.next() {
        return Err(format!("unexpected `{extra}`"));
    }
    Ok(Command::Gen {
        prompt,
        seconds,
        seed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(s: &str) -> Command {
        match parse(s) {
            Ok(Input::Command(c)) => c,
            other => panic!("{s}: {other:?}"),
        }
    }

    #[test]
    fn commands_and_aliases() {
        assert_eq!(cmd(":load a.mprog"), Command::Load("a.mprog".into()));
        assert_eq!(
            cmd(":l \"my prog.mprog\""),
            Command::Load("my prog.mprog".into())
        );
        assert_eq!(cmd(":m walk.bvh"), Command::Motion("walk.bvh".into()));
        assert_eq!(cmd(":e head.y"), Command::Eval("head.y".into()));
        assert_eq!(cmd(":grad head.y > 1"), Command::Grad("head.y > 1".into()));
        assert_eq!(cmd(":q"), Command::Quit);
        assert_eq!(cmd(":drop 3"), Command::Drop { first: 3, last: 3 });
        assert_eq!(cmd(":d 2-4"), Command::Drop { first: 2, last: 4 });
        for bad in [":drop", ":drop 0", ":drop x", ":drop 4-2", ":drop 1-"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        assert_eq!(
            cmd(":run"),
            Command::Run {
                solver: "guide".into(),
                seed: 1,
                knobs: vec![]
            }
        );
        assert_eq!(
            cmd(":run latent 7 iterations=20"),
            Command::Run {
                solver: "latent".into(),
                seed: 7,
                knobs: vec![("iterations".into(), 20.0)]
            }
        );
        assert!(parse(":run guide x y").is_err());
        assert!(parse(":run guide steps=abc").is_err());
        assert_eq!(cmd(":exit"), Command::Quit);
        assert_eq!(cmd(":?"), Command::Help(None));
        assert_eq!(cmd(":help :eval"), Command::Help(Some("eval".into())));
        assert_eq!(cmd("  :score  "), Command::Score);
    }

    #[test]
    fn gen_arguments() {
        assert_eq!(
            cmd(":gen \"a person walks\""),
            Command::Gen {
                prompt: "a person walks".into(),
                seconds: 6.0,
                seed: 1
            }
        );
        assert_eq!(
            cmd(":gen \"jump\" 3.5s 7"),
            Command::Gen {
                prompt: "jump".into(),
                seconds: 3.5,
                seed: 7
            }
        );
        for bad in [
            ":gen walk",
            ":gen \"walk",
            ":gen \"\"",
            ":gen \"w\" -1",
            ":gen \"w\" 2 x",
            ":gen \"w\" 2 3 4",
        ] {
            let e = parse(bad).unwrap_err();
            assert!(e.contains("usage: :gen"), "{bad}: {e}");
        }
    }

    #[test]
    fn wrong_commands_explain() {
        assert!(
            parse(":frobnicate")
                .unwrap_err()
                .contains("unknown command `:frobnicate`")
        );
        assert!(parse(":load").unwrap_err().contains("needs a program file"));
        assert!(
            parse(":score now")
                .unwrap_err()
                .contains("takes no argument")
        );
    }

    #[test]
    fn code_and_empty() {
        assert_eq!(parse("  # just a comment\n"), Ok(Input::Empty));
        assert_eq!(parse(""), Ok(Input::Empty));
        assert_eq!(
            parse("always { head.y > 1 }\n"),
            Ok(Input::Code("always { head.y > 1 }".into()))
        );
    }

    #[test]
    fn every_table_entry_parses() {
        for c in COMMANDS {
            let line = match c.name {
                "gen" => ":gen \"walk\"".to_string(),
                "drop" => ":drop 1".to_string(),
                _ if c.args.is_empty() || c.args.starts_with('[') => format!(":{}", c.name),
                _ => format!(":{} x", c.name),
            };
            assert!(matches!(parse(&line), Ok(Input::Command(_))), "{line}");
        }
    }
}
