//! Chi-square goodness-of-fit harness: histogram samples of a warp on a grid over its domain,
//! integrate its pdf over each cell, pool sparse cells, and compute a p-value (statrs).
//! Used by the test suite and by `penumbra warp`. TODO(issue 2): implement.
