//! Cube panorama tests (filled in below).
