//! `ppis` command line. The renderer lands with the host-std issue; until then every
//! subcommand reports that plainly and exits with status 2.

fn main() {
    let cmd = std::env::args().nth(1).unwrap_or_default();
    eprintln!(
        "ppis: `{cmd}` is not available yet: the renderer (host-std issue) has not landed; sampler-core is usable as a library"
    );
    std::process::exit(2);
}
