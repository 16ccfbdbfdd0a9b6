//! Results as a MAT-file version 4 in the layout Dymola and OpenModelica write
//! (`dsres.mat`, "binTrans"): the matrices `Aclass`, `name`, `description`, `dataInfo`,
//! `data_1` (start and stop time) and `data_2` (the trajectories), which scipy's
//! `loadmat`, DyMat, BuildingsPy and OMPython read.
//!
//! A v4 matrix is a header of five little-endian int32 (type `1000 M + 100 O + 10 P + T`
//! with M = 0 little-endian, P = 0 double / 2 int32 / 5 uint8, T = 0 numeric / 1 text;
//! rows; columns; imaginary flag; length of the name with its NUL), the name, and the
//! values column by column. "binTrans" stores every matrix transposed: each name is one
//! column of `name`, each output point one column of `data_2` (time first), so the rows
//! of [`Results`] are written as they are.

use crate::simulate::Results;
use std::io::Write;

fn header<W: Write>(w: &mut W, ty: i32, rows: usize, cols: usize, name: &str) -> std::io::Result<()> {
    let dims = |n: usize| i32::try_from(n).map_err(|_| std::io::Error::other("a MAT v4 matrix over 2^31 rows"));
    for v in [ty, dims(rows)?, dims(cols)?, 0, dims(name.len() + 1)?] {
        w.write_all(&v.to_le_bytes())?;
    }
    w.write_all(name.as_bytes())?;
    w.write_all(&[0])
}

/// A text matrix whose columns are `strings`, padded with spaces to the longest.
fn text<W: Write>(w: &mut W, name: &str, strings: &[&str]) -> std::io::Result<()> {
    let rows = strings.iter().map(|s| s.len()).max().unwrap_or(0).max(1);
    header(w, 51, rows, strings.len(), name)?;
    let mut column = Vec::with_capacity(rows);
    for s in strings {
        column.clear();
        column.extend_from_slice(s.as_bytes());
        column.resize(rows, b' ');
        w.write_all(&column)?;
    }
    Ok(())
}

impl Results {
    /// Writes the results as a MAT v4 file (see [`crate::mat`]); `descriptions` holds one
    /// description per column after time (empty strings where there is none).
    pub fn write_mat<W: Write>(&self, mut w: W, descriptions: &[String]) -> std::io::Result<()> {
        let w = &mut w;
        // Aclass: 4 rows (class, version, unused, storage), transposed: one per column
        let aclass = ["Atrajectory", "1.1", "", "binTrans"];
        let width = aclass.iter().map(|s| s.len()).max().unwrap_or(0);
        header(w, 51, aclass.len(), width, "Aclass")?;
        for j in 0..width {
            for s in aclass {
                w.write_all(&[*s.as_bytes().get(j).unwrap_or(&b' ')])?;
            }
        }
        let mut names: Vec<&str> = vec!["time"];
        names.extend(self.names.iter().map(String::as_str));
        text(w, "name", &names)?;
        let mut text_of: Vec<&str> = vec!["Time in [s]"];
        text_of.extend((0..self.names.len()).map(|k| descriptions.get(k).map_or("", String::as_str)));
        text(w, "description", &text_of)?;
        // dataInfo: per variable (matrix 1 or 2, 0 for the abscissa; column; linear
        // interpolation 0; not defined outside the interval -1)
        header(w, 20, 4, names.len(), "dataInfo")?;
        for j in 0..names.len() {
            let info: [i32; 4] = if j == 0 { [0, 1, 0, -1] } else { [2, j as i32 + 1, 0, -1] };
            for v in info {
                w.write_all(&v.to_le_bytes())?;
            }
        }
        let rows = self.rows();
        let (t0, t1) = if rows == 0 { (0.0, 0.0) } else { (self.row(0)[0], self.row(rows - 1)[0]) };
        header(w, 0, 1, 2, "data_1")?;
        w.write_all(&t0.to_le_bytes())?;
        w.write_all(&t1.to_le_bytes())?;
        header(w, 0, self.width(), rows, "data_2")?;
        let mut buffer = Vec::with_capacity(8 * self.width());
        for k in 0..rows {
            buffer.clear();
            for v in self.row(k) {
                buffer.extend_from_slice(&v.to_le_bytes());
            }
            w.write_all(&buffer)?;
        }
        w.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads back the matrices by the format's definition (header, name, column-major data).
    fn matrices(bytes: &[u8]) -> Vec<(i32, usize, usize, String, Vec<u8>)> {
        let mut out = Vec::new();
        let mut at = 0;
        let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        while at < bytes.len() {
            let (ty, rows, cols, imag, namelen) =
                (int(at), int(at + 4) as usize, int(at + 8) as usize, int(at + 12), int(at + 16) as usize);
            assert_eq!(imag, 0);
            let name = String::from_utf8(bytes[at + 20..at + 20 + namelen - 1].to_vec()).unwrap();
            let size = match ty % 100 / 10 {
                0 => 8,
                2 => 4,
                5 => 1,
                p => panic!("precision {p}"),
            };
            let start = at + 20 + namelen;
            out.push((ty, rows, cols, name, bytes[start..start + rows * cols * size].to_vec()));
            at = start + rows * cols * size;
        }
        out
    }

    #[test]
    fn dymola_layout() {
        let r = Results {
            names: vec!["x".into(), "plant.v_x".into()],
            values: vec![0.0, 1.0, 2.0, 0.5, -1.5, 1e-300],
            exact: Vec::new(),
        };
        let mut bytes = Vec::new();
        r.write_mat(&mut bytes, &["".into(), "speed".into()]).unwrap();
        let m = matrices(&bytes);
        let names: Vec<&str> = m.iter().map(|x| x.3.as_str()).collect();
        assert_eq!(names, ["Aclass", "name", "description", "dataInfo", "data_1", "data_2"]);
        // Aclass column-major: the first bytes are the first letters of the four rows
        assert_eq!((m[0].0, m[0].1, m[0].2), (51, 4, 11));
        assert_eq!(&m[0].4[..4], b"A1 b");
        // names: one per column of 9 characters ("plant.v_x"), space-padded
        assert_eq!((m[1].1, m[1].2), (9, 3));
        assert_eq!(m[1].4, b"time     x        plant.v_x".to_vec());
        assert_eq!(
            m[3].4.chunks(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect::<Vec<_>>(),
            [0, 1, 0, -1, 2, 2, 0, -1, 2, 3, 0, -1]
        );
        let f64s = |b: &[u8]| b.chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect::<Vec<_>>();
        assert_eq!(f64s(&m[4].4), [0.0, 0.5]);
        assert_eq!((m[5].0, m[5].1, m[5].2), (0, 3, 2));
        assert_eq!(f64s(&m[5].4), r.values);
    }
}
