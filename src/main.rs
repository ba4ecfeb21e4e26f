//! The `cylvol` command-line program: see `cylvol --help`. JSON goes to standard output alone;
//! progress and logs go to standard error; errors exit non-zero with a message on standard error.

mod cli;

fn main() {
    std::process::exit(cli::run());
}
