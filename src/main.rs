//! The `flatcut` binary: parse the command line, run it, map the outcome to an exit code
//! (0 done, 1 the input or environment is at fault, 2 a bug in flatcut).

use clap::Parser;
use flatcut::cli::{run, Cli};

fn main() {
    std::panic::set_hook(Box::new(|info| {
        // `println!` panics when the reader of stdout has gone (`flatcut … | head`): that is
        // the environment, not a bug. Files are written whole before anything is printed.
        let text = info.to_string();
        if text.contains("failed printing to stdout") {
            eprintln!("flatcut: standard output was closed; stopped");
            std::process::exit(1);
        }
        eprintln!("flatcut: internal error (a bug in flatcut, please report it): {info}");
        std::process::exit(2);
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 1 } else { 0 };
            let _ = e.print();
            std::process::exit(code);
        }
    };
    if let Err(e) = run(cli) {
        eprintln!("flatcut: {e}");
        std::process::exit(e.exit_code());
    }
}
