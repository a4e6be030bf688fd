//! The smallest libraries that [`super::Platform::of_library`] recognizes and whose symbol
//! table exports the given names: for tests that package stand-in engines. Their symbols point
//! nowhere; nothing loads them.

/// An ELF64 x86-64 shared object with four sections (null, `.dynsym`, `.dynstr`, `.shstrtab`)
/// and one global function symbol per name in `.dynsym`.
pub(super) fn elf(names: &[&str]) -> Vec<u8> {
    let mut dynstr = vec![0u8];
    let mut dynsym = vec![0u8; 24]; // the null symbol
    for name in names {
        let at = dynstr.len() as u32;
        dynstr.extend_from_slice(name.as_bytes());
        dynstr.push(0);
        dynsym.extend_from_slice(&at.to_le_bytes()); // st_name
        dynsym.push(0x12); // st_info: STB_GLOBAL, STT_FUNC
        dynsym.push(0); // st_other: default visibility
        dynsym.extend_from_slice(&1u16.to_le_bytes()); // st_shndx: defined (section 1)
        dynsym.extend_from_slice(&0x1000u64.to_le_bytes()); // st_value
        dynsym.extend_from_slice(&16u64.to_le_bytes()); // st_size
    }
    let shstrtab = b"\0.dynsym\0.dynstr\0.shstrtab\0";
    let align8 = |n: usize| n.div_ceil(8) * 8;
    let dynsym_at = 64;
    let dynstr_at = dynsym_at + dynsym.len();
    let shstrtab_at = dynstr_at + dynstr.len();
    let sections_at = align8(shstrtab_at + shstrtab.len());
    let mut b = vec![0u8; sections_at];
    b[..4].copy_from_slice(b"\x7fELF");
    b[4] = 2; // ELFCLASS64
    b[5] = 1; // little-endian
    b[6] = 1; // EV_CURRENT
    b[16..18].copy_from_slice(&3u16.to_le_bytes()); // ET_DYN
    b[18..20].copy_from_slice(&62u16.to_le_bytes()); // EM_X86_64
    b[20..24].copy_from_slice(&1u32.to_le_bytes());
    b[40..48].copy_from_slice(&(sections_at as u64).to_le_bytes()); // e_shoff
    b[52..54].copy_from_slice(&64u16.to_le_bytes()); // e_ehsize
    b[54..56].copy_from_slice(&56u16.to_le_bytes()); // e_phentsize
    b[58..60].copy_from_slice(&64u16.to_le_bytes()); // e_shentsize
    b[60..62].copy_from_slice(&4u16.to_le_bytes()); // e_shnum
    b[62..64].copy_from_slice(&3u16.to_le_bytes()); // e_shstrndx
    b[dynsym_at..dynstr_at].copy_from_slice(&dynsym);
    b[dynstr_at..shstrtab_at].copy_from_slice(&dynstr);
    b[shstrtab_at..shstrtab_at + shstrtab.len()].copy_from_slice(shstrtab);
    // Section headers: (name, type, offset, size, link, info, entsize).
    let headers: [(u32, u32, usize, usize, u32, u32, u64); 4] = [
        (0, 0, 0, 0, 0, 0, 0),
        (1, 11, dynsym_at, dynsym.len(), 2, 1, 24), // SHT_DYNSYM, link .dynstr
        (9, 3, dynstr_at, dynstr.len(), 0, 0, 0),   // SHT_STRTAB
        (17, 3, shstrtab_at, shstrtab.len(), 0, 0, 0),
    ];
    for (name, kind, offset, size, link, info, entsize) in headers {
        let mut h = [0u8; 64];
        h[0..4].copy_from_slice(&name.to_le_bytes());
        h[4..8].copy_from_slice(&kind.to_le_bytes());
        h[24..32].copy_from_slice(&(offset as u64).to_le_bytes());
        h[32..40].copy_from_slice(&(size as u64).to_le_bytes());
        h[40..44].copy_from_slice(&link.to_le_bytes());
        h[44..48].copy_from_slice(&info.to_le_bytes());
        h[48..56].copy_from_slice(&u64::from(kind != 0).to_le_bytes()); // sh_addralign
        h[56..64].copy_from_slice(&entsize.to_le_bytes());
        b.extend_from_slice(&h);
    }
    b
}

/// A PE32+ x86-64 DLL (NT headers at 0x80) with one section, `.edata`, that holds an export
/// table of the names.
pub(super) fn pe(names: &[&str]) -> Vec<u8> {
    const PE: usize = 0x80;
    const OPTIONAL: usize = PE + 24;
    const SECTION_TABLE: usize = OPTIONAL + 240;
    const RAW: usize = 0x200; // file offset of the section's bytes
    const RVA: u32 = 0x1000; // its address in the image
    let n = names.len() as u32;
    // .edata: directory (40), functions (4n), name pointers (4n), ordinals (2n), names.
    let functions = 40u32;
    let pointers = functions + 4 * n;
    let ordinals = pointers + 4 * n;
    let mut strings = ordinals + 2 * n;
    let mut edata = Vec::new();
    let dll_name = strings;
    strings += b"fmu_beam.dll\0".len() as u32;
    let words: [u32; 10] = [
        0,
        0,
        0, // major, minor version (two u16)
        RVA + dll_name,
        1, // ordinal base
        n,
        n,
        RVA + functions,
        RVA + pointers,
        RVA + ordinals,
    ];
    for w in words {
        edata.extend_from_slice(&w.to_le_bytes());
    }
    for _ in names {
        edata.extend_from_slice(&0x2000u32.to_le_bytes()); // outside .edata: not a forward
    }
    let mut at = strings;
    for name in names {
        edata.extend_from_slice(&(RVA + at).to_le_bytes());
        at += name.len() as u32 + 1;
    }
    for i in 0..n {
        edata.extend_from_slice(&(i as u16).to_le_bytes());
    }
    edata.extend_from_slice(b"fmu_beam.dll\0");
    for name in names {
        edata.extend_from_slice(name.as_bytes());
        edata.push(0);
    }
    let raw_size = edata.len().div_ceil(0x200) * 0x200;
    let mut b = vec![0u8; RAW + raw_size];
    b[..2].copy_from_slice(b"MZ");
    b[0x3c..0x40].copy_from_slice(&(PE as u32).to_le_bytes());
    b[PE..PE + 4].copy_from_slice(b"PE\0\0");
    b[PE + 4..PE + 6].copy_from_slice(&0x8664u16.to_le_bytes()); // AMD64
    b[PE + 6..PE + 8].copy_from_slice(&1u16.to_le_bytes()); // one section
    b[PE + 20..PE + 22].copy_from_slice(&240u16.to_le_bytes()); // optional header size
    b[PE + 22..PE + 24].copy_from_slice(&0x2022u16.to_le_bytes()); // DLL, executable, large
    let o = OPTIONAL;
    b[o..o + 2].copy_from_slice(&0x20bu16.to_le_bytes()); // PE32+
    b[o + 24..o + 32].copy_from_slice(&0x1_8000_0000u64.to_le_bytes()); // image base
    b[o + 32..o + 36].copy_from_slice(&0x1000u32.to_le_bytes()); // section alignment
    b[o + 36..o + 40].copy_from_slice(&0x200u32.to_le_bytes()); // file alignment
    let image = RVA + (edata.len() as u32).div_ceil(0x1000) * 0x1000;
    b[o + 56..o + 60].copy_from_slice(&image.to_le_bytes()); // size of image
    b[o + 60..o + 64].copy_from_slice(&(RAW as u32).to_le_bytes()); // size of headers
    b[o + 68..o + 70].copy_from_slice(&2u16.to_le_bytes()); // subsystem: GUI
    b[o + 108..o + 112].copy_from_slice(&16u32.to_le_bytes()); // data directories
    b[o + 112..o + 116].copy_from_slice(&RVA.to_le_bytes()); // export table
    b[o + 116..o + 120].copy_from_slice(&(edata.len() as u32).to_le_bytes());
    let s = SECTION_TABLE;
    b[s..s + 8].copy_from_slice(b".edata\0\0");
    b[s + 8..s + 12].copy_from_slice(&(edata.len() as u32).to_le_bytes()); // virtual size
    b[s + 12..s + 16].copy_from_slice(&RVA.to_le_bytes());
    b[s + 16..s + 20].copy_from_slice(&(raw_size as u32).to_le_bytes());
    b[s + 20..s + 24].copy_from_slice(&(RAW as u32).to_le_bytes());
    b[s + 36..s + 40].copy_from_slice(&0x4000_0040u32.to_le_bytes()); // read, initialized data
    b[RAW..RAW + edata.len()].copy_from_slice(&edata);
    b
}
