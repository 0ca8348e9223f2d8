//! The report's answer at its operating point, three lines at the top of `report.md` and
//! `report.html`: the cheapest configuration within 10% of the best penumbra error, the most
//! accurate within a stated time budget per light, and prefiltering against PCSS there. And
//! the families the plots draw with one marker shape each.

use super::{Measurement, Report};

/// How much worse than the best penumbra error a configuration may be and still count as
/// "as accurate" (10%).
pub const NEAR_BEST: f64 = 1.10;

/// The time budget per light on a GPU when none is given, ms.
pub const GPU_BUDGET_MS: f64 = 1.0;

/// What a technique does per frame: the plots' marker shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// One lookup or a fixed kernel per pixel, hard-edged: hard, PCF, second depth.
    Lookup,
    /// A per-pixel blocker search for a soft shadow: PCSS, SMRT.
    Search,
    /// A filterable representation, prefiltered: VSM, EVSM, ESM, MSM, CSM.
    Prefiltered,
    /// A prefiltered table read at a per-pixel width: the soft techniques.
    PrefilteredSoft,
}

impl Family {
    /// Every family, in legend order.
    pub const ALL: [Family; 4] = [
        Family::Lookup,
        Family::Search,
        Family::Prefiltered,
        Family::PrefilteredSoft,
    ];

    /// The family of a technique: whether it stores a representation, and whether it needs
    /// an area light.
    pub fn of(technique: &crate::model::Technique) -> Self {
        let soft = crate::technique::by_name(technique.name()).is_some_and(|d| d.area_light);
        match (technique.storage().is_some(), soft) {
            (false, false) => Family::Lookup,
            (false, true) => Family::Search,
            (true, false) => Family::Prefiltered,
            (true, true) => Family::PrefilteredSoft,
        }
    }

    /// The name a row keeps ([`Measurement::family`]).
    pub fn name(self) -> &'static str {
        match self {
            Family::Lookup => "lookup",
            Family::Search => "search",
            Family::Prefiltered => "prefiltered",
            Family::PrefilteredSoft => "prefiltered soft",
        }
    }

    /// The family named `name` (a row of an older report has none: a lookup).
    pub fn named(name: &str) -> Self {
        Family::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .unwrap_or(Family::Lookup)
    }

    /// Whether it prefilters.
    pub fn prefilters(self) -> bool {
        matches!(self, Family::Prefiltered | Family::PrefilteredSoft)
    }
}

/// The operating point in words: image, lights, how often the maps change.
pub fn operating_point(report: &Report) -> String {
    let mut rates = report.updates.clone();
    rates.dedup();
    let how = match rates.as_slice() {
        [] => "every map redrawn and refiltered every frame".to_string(),
        [one] => rate_words(one),
        _ => format!("maps redrawn at update = {}", report.updates.join(", ")),
    };
    format!(
        "{}×{}, {} light{}, {how}",
        report.image.0,
        report.image.1,
        report.lights.max(1),
        if report.lights == 1 { "" } else { "s" }
    )
}

/// An update rate as the scene file writes it (`1`, `k`, `"static"`) in words.
fn rate_words(rate: &str) -> String {
    match rate {
        "1" => "every map redrawn and refiltered every frame".into(),
        "\"static\"" => "static lights: maps drawn once and kept".into(),
        k => format!("maps redrawn and refiltered every {k} frames"),
    }
}

/// The budget per light the verdict uses, and how it was chosen: the report's, else 1 ms on
/// a GPU, else (a CPU driver, whose times no frame budget applies to) the median
/// configuration's time per light.
pub fn budget(report: &Report) -> Option<(f64, &'static str)> {
    if let Some(b) = report.budget_ms {
        return Some((b, "given"));
    }
    if !report.cpu_driver {
        return Some((GPU_BUDGET_MS, "a GPU's default"));
    }
    let per_light: Vec<f64> = timed(report).map(|r| per_light(report, r)).collect();
    super::protocol::median(&per_light).map(|m| (m, "the median configuration's time"))
}

fn per_light(report: &Report, r: &Measurement) -> f64 {
    r.total_ms.unwrap_or(f64::INFINITY) / report.lights.max(1) as f64
}

/// Rows with a total time and a penumbra.
fn timed(report: &Report) -> impl Iterator<Item = &Measurement> {
    report
        .rows
        .iter()
        .filter(|r| r.total_ms.is_some_and(f64::is_finite) && r.penumbra.pixels > 0)
}

/// The fastest of `rows` (`None` when empty).
fn fastest<'a>(rows: impl Iterator<Item = &'a Measurement>) -> Option<&'a Measurement> {
    rows.min_by(|a, b| {
        let t = |r: &Measurement| r.total_ms.unwrap_or(f64::INFINITY);
        t(a).total_cmp(&t(b))
    })
}

/// The most accurate in the penumbra of `rows`.
fn most_accurate<'a>(rows: impl Iterator<Item = &'a Measurement>) -> Option<&'a Measurement> {
    rows.min_by(|a, b| a.penumbra.mean_abs.total_cmp(&b.penumbra.mean_abs))
}

fn describe(r: &Measurement) -> String {
    format!(
        "**{}** ({:.3} ms, penumbra error {:.4})",
        r.label,
        r.total_ms.unwrap_or(f64::NAN),
        r.penumbra.mean_abs
    )
}

/// The verdict lines (Markdown: `**` marks the configurations), empty without timed rows.
pub fn verdicts(report: &Report) -> Vec<String> {
    let Some(best) = most_accurate(timed(report)) else {
        return Vec::new();
    };
    let limit = NEAR_BEST * best.penumbra.mean_abs;
    let mut out = vec![format!("Operating point: {}.", operating_point(report))];
    if let Some(c) = fastest(timed(report).filter(|r| r.penumbra.mean_abs <= limit)) {
        out.push(format!(
            "Cheapest within 10% of the best penumbra error ({:.4}, {}): {}.",
            best.penumbra.mean_abs,
            best.label,
            describe(c)
        ));
    }
    if let Some((b, how)) = budget(report) {
        let fits = timed(report).filter(|r| per_light(report, r) <= b);
        match most_accurate(fits) {
            Some(r) => out.push(format!(
                "Most accurate within {b:.3} ms per light ({how}): {}.",
                describe(r)
            )),
            None => out.push(format!(
                "Most accurate within {b:.3} ms per light ({how}): none fits."
            )),
        }
    }
    if let Some(line) = against_pcss(report) {
        out.push(line);
    }
    out
}

/// Prefiltering against PCSS at this operating point: PCSS's most accurate configuration
/// against the cheapest prefiltered one at most 10% worse, or the closest if none is.
fn against_pcss(report: &Report) -> Option<String> {
    let pcss = most_accurate(timed(report).filter(|r| r.technique == "pcss"))?;
    let pre = || timed(report).filter(|r| Family::named(&r.family).prefilters());
    let t = |r: &Measurement| r.total_ms.unwrap_or(f64::NAN);
    let ratio = |r: &Measurement| t(r) / t(pcss);
    let limit = NEAR_BEST * pcss.penumbra.mean_abs;
    Some(
        match fastest(pre().filter(|r| r.penumbra.mean_abs <= limit)) {
            Some(r) => format!(
                "Prefiltering against PCSS: {} {} PCSS's best, {}, at {:.2}× its time.",
                describe(r),
                if r.penumbra.mean_abs <= pcss.penumbra.mean_abs {
                    "is at least as accurate as"
                } else {
                    "is within 10% of"
                },
                describe(pcss),
                ratio(r)
            ),
            None => match most_accurate(pre()) {
                Some(r) => format!(
                    "Prefiltering against PCSS: no prefiltered configuration comes within 10% of \
                     PCSS's best, {}; the closest, {}, is {:.2}× its error at {:.2}× its time.",
                    describe(pcss),
                    describe(r),
                    r.penumbra.mean_abs / pcss.penumbra.mean_abs.max(f64::MIN_POSITIVE),
                    ratio(r)
                ),
                None => format!(
                    "Prefiltering against PCSS: no prefiltered configuration was measured (PCSS's \
                     best: {}).",
                    describe(pcss)
                ),
            },
        },
    )
}
