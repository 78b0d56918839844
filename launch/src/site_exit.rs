//! [`SiteExit`]: a node's end as the machine it ran on reported it,
//! described in words because it may have crossed machines.

/// A node's end on a site (this machine or another), as the site reported it.
#[derive(Debug, Clone)]
pub struct SiteExit {
    /// The node's id.
    pub id: u32,
    /// The machine it ran on.
    pub host: String,
    /// Its exit, described.
    pub status: String,
    /// It exited with code 0.
    pub clean: bool,
    /// The last lines of its log.
    pub tail: String,
}
