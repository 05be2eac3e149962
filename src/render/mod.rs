//! Pictures: stick-figure GIF/PNG renders of motions and line plots.
