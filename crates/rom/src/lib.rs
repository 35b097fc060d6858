//! rom
