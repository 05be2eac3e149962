//! Contacts a program asks for: two joints (usually of two people) that should touch over
//! a range of frames; drawn by the viewer.

/// One end of a contact: a joint of a person.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointOf {
    /// Index into the people.
    pub person: usize,
    /// HumanML3D joint index.
    pub joint: usize,
}

/// Two joints (usually of two people) that should touch over a range of frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// Shown beside the line when active.
    pub label: Option<String>,
    /// One end.
    pub a: JointOf,
    /// The other end.
    pub b: JointOf,
    /// First and last frame (inclusive) where the contact is active.
    pub frames: (usize, usize),
}
