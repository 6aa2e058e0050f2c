//! `gmwm`: command-line front end. IN PROGRESS (lead).
fn main() {}
