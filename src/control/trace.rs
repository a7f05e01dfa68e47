//! The sequence of commands a controller run issued: what makes runs comparable and repeatable.

use serde::{Deserialize, Serialize};

use crate::pose::PadPose;

/// Which controller issued a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Command {
    Approach,
    Press,
    Orient,
}

/// Commanded pad poses in order.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    pub commands: Vec<(Command, PadPose)>,
}

impl Trace {
    pub fn push(&mut self, command: Command, pose: PadPose) {
        self.commands.push((command, pose));
    }

    /// How many commands of `kind` were issued.
    pub fn count(&self, kind: Command) -> usize {
        self.commands.iter().filter(|(c, _)| *c == kind).count()
    }
}
