//! A minimal writer of NumPy `.npy` files (format version 1.0, little-endian f64, C order), so that
//! trajectories open with `numpy.load` without any dependency on our side.

use std::io::{self, Write};

/// Writes `data` (C order, `shape.iter().product()` values) as a `.npy` array.
pub fn write_npy(w: &mut impl Write, shape: &[usize], data: &[f64]) -> io::Result<()> {
    let n: usize = shape.iter().product();
    if n != data.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("npy: shape {shape:?} holds {n} values, got {}", data.len()),
        ));
    }
    let dims = match shape.len() {
        1 => format!("({},)", shape[0]),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {dims}, }}");
    // magic (6) + version (2) + header length (2) + header + '\n' is a multiple of 64
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    w.write_all(b"\x93NUMPY\x01\x00")?;
    w.write_all(&(header.len() as u16).to_le_bytes())?;
    w.write_all(header.as_bytes())?;
    let mut buf = Vec::with_capacity(8 * data.len());
    for v in data {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_aligned_and_data_follows() {
        let mut out = Vec::new();
        write_npy(&mut out, &[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        assert_eq!(&out[..8], b"\x93NUMPY\x01\x00");
        let hl = u16::from_le_bytes([out[8], out[9]]) as usize;
        assert_eq!((10 + hl) % 64, 0);
        let header = std::str::from_utf8(&out[10..10 + hl]).unwrap();
        assert!(header.contains("'shape': (2, 3)") && header.ends_with('\n'));
        assert_eq!(out.len(), 10 + hl + 48);
        assert_eq!(
            f64::from_le_bytes(out[10 + hl + 40..].try_into().unwrap()),
            6.0
        );
        let mut out = Vec::new();
        write_npy(&mut out, &[4], &[0.0; 4]).unwrap();
        assert!(std::str::from_utf8(&out[10..74]).unwrap().contains("(4,)"));
        assert!(write_npy(&mut Vec::new(), &[3], &[1.0]).is_err());
    }
}
