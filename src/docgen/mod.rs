//! Documentation generated from the code, so it cannot drift: the LLM system prompt
//! (`mprog prompt`), the library reference, the cookbook pages and the reference tables
//! (output kinds, solver knobs) of the book (`mprog doc book`). Tests compare the book's generated pages with these functions and
//! compile every example they embed.

pub mod book;
pub mod library;
pub mod markdown;
pub mod prompt;
pub mod tables;
