//! The summary of the committed evaluations in docs/MEASURED.md: for each scene's
//! `report.csv` under a directory (`benches/evaluation/<scene>/`), which techniques lie on the
//! Pareto front of total time against the penumbra error and against FLIP, fastest first, with
//! the fastest and the most accurate configuration of each front. `tests/readme_fronts.rs`
//! checks that docs/MEASURED.md's table is this text for the committed reports.

use std::fmt::Write as _;
use std::path::Path;

use super::pareto_front;
use crate::error::{Error, Result};

/// One configuration of a report: what the summary reads of its CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The configuration's label (`pcss 16+32 512`).
    pub label: String,
    /// Its technique's name.
    pub technique: String,
    /// Total time (raster + kernels + shading), ms; `None` where the device could not time.
    pub total_ms: Option<f64>,
    /// Mean |visibility − truth| over the truth's penumbra.
    pub penumbra: f64,
    /// Mean FLIP of the shaded image against the truth-shaded one.
    pub flip: f64,
}

/// The rows of a `report.csv` (as `evaluate` writes it), by its header's column names.
pub fn read_csv(text: &str, what: &str) -> Result<Vec<Point>> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| Error::Invalid(format!("{what}: empty report")))?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| Error::Invalid(format!("{what}: no column `{name}`")))
    };
    let (label, technique, total, penumbra, flip) = (
        col("label")?,
        col("technique")?,
        col("total_ms")?,
        col("penumbra_mean_abs")?,
        col("flip_mean_abs")?,
    );
    lines
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, line)| {
            let f: Vec<&str> = line.split(',').collect();
            let num = |c: usize| -> Result<f64> {
                f.get(c)
                    .and_then(|v| v.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        Error::Invalid(format!(
                            "{what}: line {}: column {} is not a number",
                            i + 2,
                            header[c]
                        ))
                    })
            };
            Ok(Point {
                label: f.get(label).unwrap_or(&"").to_string(),
                technique: f.get(technique).unwrap_or(&"").to_string(),
                total_ms: f
                    .get(total)
                    .filter(|v| !v.is_empty())
                    .map(|_| num(total))
                    .transpose()?,
                penumbra: num(penumbra)?,
                flip: num(flip)?,
            })
        })
        .collect()
}

/// One front, fastest first: its techniques (each once, in front order), the fastest and the
/// most accurate configuration.
fn front_cells(points: &[Point], error: impl Fn(&Point) -> f64) -> [String; 3] {
    let pts: Vec<(Option<f64>, f64)> = points.iter().map(|p| (p.total_ms, error(p))).collect();
    let front = pareto_front(&pts);
    let mut techniques: Vec<&str> = Vec::new();
    for &i in &front {
        if !techniques.contains(&points[i].technique.as_str()) {
            techniques.push(&points[i].technique);
        }
    }
    let label = |i: Option<&usize>| i.map_or("—".to_string(), |&i| points[i].label.clone());
    [
        techniques.join(", "),
        label(front.first()),
        label(front.last()),
    ]
}

/// The summary table (Markdown) of the reports `scene → report.csv text`, in the given order.
pub fn fronts_table(reports: &[(String, String)]) -> Result<String> {
    let mut s = String::from(
        "| scene | penumbra front: techniques | fastest | most accurate | FLIP front: techniques | fastest | most accurate |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for (scene, csv) in reports {
        let points = read_csv(csv, scene)?;
        let [pt, pf, pa] = front_cells(&points, |p| p.penumbra);
        let [ft, ff, fa] = front_cells(&points, |p| p.flip);
        let _ = writeln!(s, "| {scene} | {pt} | {pf} | {pa} | {ft} | {ff} | {fa} |");
    }
    Ok(s)
}

/// [`fronts_table`] of every `<dir>/<scene>/report.csv`, scenes in name order.
pub fn fronts_table_of(dir: &Path) -> Result<String> {
    let mut scenes: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::Invalid(format!("{}: {e}", dir.display())))?
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("report.csv").is_file())
        .map(|e| e.file_name().to_string_lossy().to_string())
        .collect();
    scenes.sort();
    let reports = scenes
        .into_iter()
        .map(|scene| {
            let path = dir.join(&scene).join("report.csv");
            let text = std::fs::read_to_string(&path)
                .map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))?;
            Ok((scene, text))
        })
        .collect::<Result<Vec<_>>>()?;
    fronts_table(&reports)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The front against a direct count: a row is on it when no other row is at most as slow
    /// and at most as wrong; rows without a time are left out.
    #[test]
    fn fronts_are_the_undominated_rows() {
        let csv = "label,technique,total_ms,penumbra_mean_abs,flip_mean_abs\n\
                   a 512,hard,1.0,0.30,0.010\n\
                   b 512,pcf,2.0,0.20,0.020\n\
                   c 512,pcf,3.0,0.25,0.005\n\
                   d 512,vsm,4.0,0.10,0.030\n\
                   e 512,pcss,,0.01,0.001\n";
        let table = fronts_table(&[("toy".into(), csv.into())]).expect("table");
        let row = table.lines().nth(2).expect("row");
        assert_eq!(
            row,
            "| toy | hard, pcf, vsm | a 512 | d 512 | hard, pcf | a 512 | c 512 |"
        );
        assert!(read_csv("label,technique\nx,y\n", "bad").is_err());
        assert!(
            read_csv(
                "label,technique,total_ms,penumbra_mean_abs,flip_mean_abs\nx,y,1,NaN,0\n",
                "nan"
            )
            .is_err()
        );
    }
}
