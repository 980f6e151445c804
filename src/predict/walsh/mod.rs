//! The Walsh forms: fixed and drawn patterns under a digital shift, linear nets, and the transform.

pub(crate) mod forms;
pub(crate) mod linear_net;
pub(crate) mod walsh_net;
pub(crate) mod walsh_transform;
