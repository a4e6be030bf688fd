//! The FMI logger's message is a printf format (`fmi2CallbackLogger(…, message, ...)`): the
//! master prints it formatted, as every importer does. The master's logger cannot read the
//! variadic arguments (stable Rust has no variadic `extern "C" fn`), so [`printf`] formats what
//! needs none: `%%` is one `%`; a directive that would consume an argument is kept as written,
//! so the reader sees where a foreign FMU meant a value.

/// `format` as printf prints it without arguments: `%%` → `%`, every other conversion
/// specification (`%d`, `%-8.3f`, `%lu`, `%s` …) left as it is, a lone `%` at the end kept.
pub fn printf(format: &str) -> String {
    let mut out = String::with_capacity(format.len());
    let mut rest = format;
    while let Some(at) = rest.find('%') {
        out.push_str(&rest[..at]);
        let spec = &rest[at..];
        let len = directive_len(spec);
        if &spec[..len] == "%%" {
            out.push('%');
        } else {
            out.push_str(&spec[..len]);
        }
        rest = &spec[len..];
    }
    out.push_str(rest);
    out
}

/// The length in bytes of the conversion specification at the start of `spec` (which starts
/// with `%`): flags, width, precision, length modifier and the conversion; as far as it goes
/// when the text ends or breaks off first.
fn directive_len(spec: &str) -> usize {
    let bytes = spec.as_bytes();
    let mut i = 1;
    if bytes.get(i) == Some(&b'%') {
        return 2;
    }
    let skip = |i: &mut usize, set: &[u8]| {
        while bytes.get(*i).is_some_and(|b| set.contains(b)) {
            *i += 1;
        }
    };
    skip(&mut i, b"-+ #0'");
    skip(&mut i, b"0123456789*");
    if bytes.get(i) == Some(&b'.') {
        i += 1;
        skip(&mut i, b"0123456789*");
    }
    skip(&mut i, b"hlLqjzt");
    match bytes.get(i) {
        Some(b) if b"diouxXeEfFgGaAcspn".contains(b) => i + 1,
        _ => i,
    }
}

#[cfg(test)]
mod tests {
    use super::printf;

    #[test]
    fn a_doubled_percent_prints_as_one() {
        assert_eq!(printf("7.9 %% of the budget"), "7.9 % of the budget");
        assert_eq!(printf("100%%"), "100%");
        assert_eq!(printf("%%%%"), "%%");
    }

    #[test]
    fn directives_that_need_an_argument_are_kept() {
        assert_eq!(printf("x = %d, %-8.3f%s"), "x = %d, %-8.3f%s");
        assert_eq!(printf("%lu items, 5%% done"), "%lu items, 5% done");
        assert_eq!(printf("ends with %"), "ends with %");
        assert_eq!(printf("%5"), "%5");
        assert_eq!(printf("ü %% ß"), "ü % ß");
    }
}
