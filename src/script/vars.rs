//! Variables (in progress).
/// The variable store.
#[derive(Default, Debug, Clone)]
pub struct Variables {}
