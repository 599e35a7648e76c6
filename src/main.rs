//! jointquake command line (thin: parses arguments, calls the library, adds anyhow context).
fn main() {}
