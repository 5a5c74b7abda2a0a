//! One way to check every stage's settings: a params type is checked once
//! into its valid form, and its error names the field at fault, so each
//! front-end can name its own option for it (a command-line flag, a
//! Python keyword) without the library knowing either.

/// Settings of one stage, checked once before use.
pub trait Params {
    /// What passed the check: the only form the stage accepts.
    type Valid;
    type Error: InvalidField;
    /// Every rule has its own error.
    fn check(&self) -> Result<Self::Valid, Self::Error>;
}

/// A setting out of range. Its message reads `FIELD: RULE`, naming the
/// params field at fault.
pub trait InvalidField: std::error::Error {
    /// The params field at fault (for a rule over two fields, the one the
    /// message is about).
    fn field(&self) -> &'static str;

    /// The message with the field replaced by `option`, a front-end's name
    /// for it (`--min-length`, `min_length`).
    fn naming(&self, option: &str) -> String {
        let text = self.to_string();
        let rule = text.strip_prefix(self.field()).and_then(|t| t.strip_prefix(": ")).unwrap_or(&text);
        format!("{option}: {rule}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("{}: must be positive", self.field())]
    struct Negative;

    impl InvalidField for Negative {
        fn field(&self) -> &'static str {
            "length_s"
        }
    }

    #[test]
    fn a_front_end_names_its_own_option() {
        assert_eq!(Negative.to_string(), "length_s: must be positive");
        assert_eq!(Negative.naming("--length"), "--length: must be positive");
    }
}
