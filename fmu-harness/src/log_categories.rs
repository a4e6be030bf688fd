//! The log categories the FMU declares in modelDescription.xml: the engine's own list, so the
//! XML and the categories fmi2SetDebugLogging accepts can never disagree.

pub use fmu_beam::LOG_CATEGORIES;

#[cfg(test)]
mod tests {
    use super::LOG_CATEGORIES;

    #[test]
    fn the_standard_categories_and_log_all() {
        let names: Vec<&str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "logEvents",
                "logInformation",
                "logStatusWarning",
                "logStatusDiscard",
                "logStatusError",
                "logStatusFatal",
                "logAll"
            ]
        );
    }
}
