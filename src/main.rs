//! The `cylvol` command-line program.

fn main() {
    std::process::exit(cylvol_cli::run());
}

mod cylvol_cli {
    pub fn run() -> i32 {
        0
    }
}
