//! Seeded simulation (METHODS §10). Issue 2 carries only the small demo generator; the full
//! process simulator arrives with the process layer.
