//! The FMU's GUID: a digest of what the FMU contains, so the same scene and binary always give
//! the same GUID and any change gives another.

use sha2::{Digest, Sha256};

/// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}` from the first 16 bytes of SHA-256 over the parts,
/// concatenated in order.
pub fn guid(parts: &[&[u8]]) -> String {
    let mut hasher = Sha256::new();
    for p in parts {
        hasher.update(p);
    }
    let digest = hasher.finalize();
    let hex: String = digest[..16].iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

#[cfg(test)]
mod tests {
    use super::guid;

    #[test]
    fn uuid_shape_and_known_digest() {
        // sha256("") = e3b0c442 98fc 1c14 9afb f4c8996fb924...
        assert_eq!(guid(&[]), "{e3b0c442-98fc-1c14-9afb-f4c8996fb924}");
        assert_eq!(guid(&[b"ab", b"c"]), guid(&[b"abc"]));
        assert_ne!(guid(&[b"abc"]), guid(&[b"abd"]));
    }
}
