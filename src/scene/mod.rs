//! scene (in progress).
