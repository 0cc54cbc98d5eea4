//! VTK's XML formats for ParaView: an unstructured grid (`.vtu`) of particles as VTK_VERTEX
//! cells, one per particle, its arrays base64-encoded binary (little-endian, a UInt64 byte
//! count before each array, encoded apart from it, as VTK writes them), and the collection
//! (`.pvd`) that makes a time series of `.vtu` files. Checked with meshio's reader.

use std::io::Write;

/// The values of a point-data array.
pub enum Values<'a> {
    F64(&'a [f64]),
    I32(&'a [i32]),
}

/// A point-data array: its name, components per point and values (point after point).
pub struct Array<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: Values<'a>,
}

/// A value of a frame's field data (one number for the whole grid).
pub struct Field<'a> {
    pub name: &'a str,
    pub value: f64,
}

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648, with padding) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Write one binary DataArray: the UInt64 byte count and the data, each base64-encoded.
fn data_array(w: &mut impl Write, attributes: &str, bytes: &[u8]) -> std::io::Result<()> {
    writeln!(
        w,
        "        <DataArray {attributes} format=\"binary\">{}{}</DataArray>",
        base64(&(bytes.len() as u64).to_le_bytes()),
        base64(bytes)
    )
}

fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The name of an array as an XML attribute value (sppm's names need no escaping; any
/// other character than a letter, digit or underscore becomes an underscore).
fn attribute(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// Write a `.vtu` file of `points` (m) as vertex cells with `arrays` as point data and
/// `fields` as field data. Each array must hold `components` values per point.
pub fn write_vtu(
    w: &mut impl Write,
    points: &[[f64; 3]],
    arrays: &[Array],
    fields: &[Field],
) -> std::io::Result<()> {
    let n = points.len();
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    if !fields.is_empty() {
        writeln!(w, "    <FieldData>")?;
        for f in fields {
            data_array(
                w,
                &format!(
                    "type=\"Float64\" Name=\"{}\" NumberOfTuples=\"1\"",
                    attribute(f.name)
                ),
                &f.value.to_le_bytes(),
            )?;
        }
        writeln!(w, "    </FieldData>")?;
    }
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">"
    )?;
    writeln!(w, "      <PointData>")?;
    for a in arrays {
        let (kind, bytes, len) = match &a.values {
            Values::F64(v) => ("Float64", f64_bytes(v), v.len()),
            Values::I32(v) => (
                "Int32",
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
                v.len(),
            ),
        };
        debug_assert_eq!(len, n * a.components, "{}", a.name);
        data_array(
            w,
            &format!(
                "type=\"{kind}\" Name=\"{}\" NumberOfComponents=\"{}\"",
                attribute(a.name),
                a.components
            ),
            &bytes,
        )?;
    }
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <Points>")?;
    let xyz: Vec<f64> = points.iter().flatten().copied().collect();
    data_array(
        w,
        "type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"",
        &f64_bytes(&xyz),
    )?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Cells>")?;
    let ints = |f: &dyn Fn(i64) -> i64| -> Vec<u8> {
        (0..n as i64).flat_map(|i| f(i).to_le_bytes()).collect()
    };
    data_array(w, "type=\"Int64\" Name=\"connectivity\"", &ints(&|i| i))?;
    data_array(w, "type=\"Int64\" Name=\"offsets\"", &ints(&|i| i + 1))?;
    // cell type 1: VTK_VERTEX
    data_array(w, "type=\"UInt8\" Name=\"types\"", &vec![1u8; n])?;
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")?;
    Ok(())
}

/// The text of a `.pvd` collection listing `(timestep, file)` pairs, the file names relative
/// to the `.pvd` file's folder.
pub fn pvd(frames: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in frames {
        s.push_str(&format!(
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{file}\"/>\n"
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::base64;

    /// RFC 4648's test vectors.
    #[test]
    fn base64_of_the_rfc_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain:?}");
        }
    }
}
