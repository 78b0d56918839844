//! `errors.svg`: attitude and angular-velocity errors per agent against
//! time, log scale, like the paper's figures (Section `simulation`); where
//! the scheme has an observer, its errors `|R̂ᵢ R₀ᵀ|_I` and `‖ω̂ᵢ − ω₀‖` in
//! two more panels; on request (`[output] torque_plot = true`), the torque
//! each agent applied, `‖τᵢ‖`, in a third panel after the first two (the
//! samples with a torque: not the last); in real-time runs, the age of information of every
//! link (mean and largest, as `summary.json` `links[]` has them: the runs
//! record no time series of it). A network of more than
//! [`EACH_AGENT_UP_TO`] agents is drawn as the band of its agents' errors,
//! and every line is thinned to [`POINTS_PER_LINE`] points (`envelope.rs`).
//!
//! Every agent has the look [`super::palette`] gives it (a colour-blind-safe
//! colour and a dash pattern), the same as in the 3D view and `Run.plot()`;
//! every panel names its quantity on its y axis, in the paper's symbols.
//!
//! Also the look every attsync chart shares (`errors.svg` here, `mc.svg` in
//! `mc/plot.rs`): `canvas`, `chart`, `line`, `bars`, `legend`.

use super::Series;
use super::envelope::{Band, EACH_AGENT_UP_TO, POINTS_PER_LINE, band, decimate};
use super::palette;
use super::summary::LinkSummary;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Why a chart could not be drawn: the drawing backend's error, as text
/// (plotters' errors are generic over the backend).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PlotError(pub String);

impl PlotError {
    /// A drawing error `e`.
    pub fn of(e: impl std::fmt::Display) -> Self {
        Self(e.to_string())
    }
}

/// Smallest value drawn on the log axes (exact zeros are clamped to it).
const FLOOR: f64 = 1e-16;
/// Height of one panel, px.
const PANEL_HEIGHT: u32 = 450;

/// Caption and y label of the attitude-error panel (R̃ᵢ = Rᵢ R₀ᵀ).
pub const ATT: (&str, &str) = ("attitude error to the leader, R̃ᵢ = Rᵢ R₀ᵀ", "|R̃ᵢ|_I");
/// Caption and y label of the angular-velocity-error panel.
pub const ANGVEL: (&str, &str) = ("angular-velocity error to the leader", "‖ωᵢ − ω₀‖ (rad/s)");
/// Caption and y label of the observer's attitude-error panel.
pub const OBSERVER_ATT: (&str, &str) = ("attitude error of the observer", "|R̂ᵢ R₀ᵀ|_I");
/// Caption and y label of the observer's angular-velocity-error panel.
pub const OBSERVER_ANGVEL: (&str, &str) = (
    "angular-velocity error of the observer",
    "‖ω̂ᵢ − ω₀‖ (rad/s)",
);
/// Caption of the age-of-information panel.
pub const AOI: &str = "age of information per link: mean and largest (log scale)";
/// Caption and y label of the torque panel (drawn on request).
pub const TORQUE: (&str, &str) = ("applied torque", "‖τᵢ‖ (N·m)");

/// Longest title drawn, characters (a longer one ends in `…`).
const TITLE_CHARS: usize = 110;

/// The title of a run's `errors.svg`: its scenario and engine, then every
/// `--set` it was given (a delayed run is not titled as the undelayed one).
#[must_use]
pub fn title(s: &super::Summary) -> String {
    let mut t = format!("{} ({})", s.scenario, s.engine);
    if !s.overrides.is_empty() {
        t += " · ";
        t += &s.overrides.join(", ");
    }
    if t.chars().count() > TITLE_CHARS {
        t = t.chars().take(TITLE_CHARS - 1).collect::<String>() + "…";
    }
    t
}

/// A moment marked on every time axis: a vertical line, labelled in the
/// first panel (a scenario's `[[event]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// When, s.
    pub t: f64,
    /// What happened.
    pub label: String,
}

/// Draws the panels into `file` (SVG): the errors of `series` (and their
/// observer errors where they have them) with `marks` on their time axes,
/// their torques if `torque`, and the age of information of `aoi`
/// (real-time runs' links; empty: no such panel).
pub fn draw(
    file: &Path,
    title: &str,
    series: &[Series],
    aoi: &[LinkSummary],
    marks: &[Mark],
    torque: bool,
) -> Result<(), PlotError> {
    let observer = series.iter().any(|s| !s.obs_att.is_empty());
    let panels =
        2 + usize::from(torque) + if observer { 2 } else { 0 } + usize::from(!aoi.is_empty());
    let root = canvas(file, (1000, PANEL_HEIGHT * panels as u32), title)?;
    let areas = root.split_evenly((panels, 1));
    let labelled = (marks, true);
    let unlabelled = (marks, false);
    panel(&areas[0], ATT, series, labelled, |s| &s.att)?;
    panel(&areas[1], ANGVEL, series, unlabelled, |s| &s.angvel)?;
    let mut next = 2;
    if torque {
        let torques = (&torques(series)[..], t_end(series));
        panel_until(&areas[next], TORQUE, torques, unlabelled, |s| &s.att)?;
        next += 1;
    }
    if observer {
        panel(&areas[next], OBSERVER_ATT, series, unlabelled, |s| {
            &s.obs_att
        })?;
        panel(&areas[next + 1], OBSERVER_ANGVEL, series, unlabelled, |s| {
            &s.obs_angvel
        })?;
    }
    if let Some(area) = areas.last().filter(|_| !aoi.is_empty()) {
        aoi_bars(area, aoi)?;
    }
    root.present().map_err(PlotError::of)
}

/// Every agent's torque norms as the `att` of a series of its own, at the
/// samples that have one (not the last: no torque follows it).
fn torques(series: &[Series]) -> Vec<Series> {
    let with = |s: &Series| -> (Vec<f64>, Vec<f64>) {
        let points = s.t.iter().zip(&s.torque).filter(|(_, x)| x.is_finite());
        points.map(|(t, x)| (*t, *x)).unzip()
    };
    (series.iter())
        .map(|s| {
            let (t, att) = with(s);
            Series {
                id: s.id,
                t,
                att,
                ..Series::default()
            }
        })
        .collect()
}

/// The mean and largest age of information of each link, as bars (ms).
fn aoi_bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    links: &[LinkSummary],
) -> Result<(), PlotError> {
    let n = links.len();
    // Milliseconds; an unmeasured age (NaN) or zero is drawn as no bar.
    let ms = |x: f64| {
        if x.is_finite() && x > 0.0 {
            x * 1e3
        } else {
            0.0
        }
    };
    let ages = links.iter().flat_map(|l| [ms(l.aoi_mean), ms(l.aoi_max)]);
    let (lo, hi) = ages
        .filter(|&x| x > 0.0)
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo / 2.0, hi * 2.0)
    } else {
        (1e-3, 1.0)
    };
    let mut chart = chart(area, AOI, 70)
        .build_cartesian_2d(-0.5..n as f64 - 0.5, (lo..hi).log_scale())
        .map_err(PlotError::of)?;
    let label = |x: &f64| {
        let k = x.round();
        match links.get(k as usize) {
            Some(l) if (x - k).abs() < 1e-9 && k >= 0.0 => format!("{}→{}", l.from, l.to),
            _ => String::new(),
        }
    };
    chart
        .configure_mesh()
        .x_desc("link (from → to, 0 = leader)")
        .x_labels(n.min(40) + 1)
        .x_label_formatter(&label)
        .y_desc("age of information (ms)")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(PlotError::of)?;
    let kinds = [
        ("mean age", 0.0, palette::colour(0)),
        ("largest age", 0.4, palette::colour(1)),
    ];
    for (name, off, color) in kinds {
        let color = color.to_rgba();
        let pick = |l: &LinkSummary| if off == 0.0 { l.aoi_mean } else { l.aoi_max };
        let rects = (links.iter().enumerate())
            .filter(|(_, l)| ms(pick(l)) > 0.0)
            .map(|(k, l)| {
                let x = k as f64 - 0.4 + off;
                Rectangle::new([(x, lo), (x + 0.4, ms(pick(l)))], color.filled())
            });
        bars(&mut chart, rects, name, color.filled(), 16)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)
}

/// The last sample time of `series` (at least 1 ns: an axis needs a length).
fn t_end(series: &[Series]) -> f64 {
    series
        .iter()
        .filter_map(|s| s.t.last().copied())
        .fold(0.0_f64, f64::max)
        .max(1e-9)
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    label: (&str, &str),
    series: &[Series],
    marks: (&[Mark], bool),
    pick: impl Fn(&Series) -> &[f64],
) -> Result<(), PlotError> {
    panel_until(area, label, (series, t_end(series)), marks, pick)
}

/// [`panel`] with a time axis to `t_end`.
fn panel_until<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (caption, y): (&str, &str),
    (series, t_end): (&[Series], f64),
    (marks, labelled): (&[Mark], bool),
    pick: impl Fn(&Series) -> &[f64],
) -> Result<(), PlotError> {
    let values = series.iter().flat_map(|s| pick(s).iter().copied());
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.max(FLOOR)), hi.max(v.max(FLOOR)))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo / 2.0, hi * 2.0)
    } else {
        (FLOOR, 1.0)
    };
    let mut chart = chart(area, caption, 90)
        .build_cartesian_2d(0.0..t_end, (lo..hi).log_scale())
        .map_err(PlotError::of)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(y)
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(PlotError::of)?;
    if series.len() > EACH_AGENT_UP_TO {
        band_of_agents(&mut chart, series.len(), &band(series, &pick))?;
    } else {
        for (k, s) in series.iter().enumerate() {
            let style = palette::colour(k).stroke_width(2);
            let points = decimate(&s.t, pick(s), POINTS_PER_LINE);
            let name = format!("agent {}", s.id);
            dashed(&mut chart, floored(points), (style, palette::dash(k)), name)?;
        }
    }
    mark(&mut chart, marks, (lo, hi), labelled)?;
    legend(&mut chart, SeriesLabelPosition::UpperRight)
}

/// `marks` as grey vertical lines over `lo..hi`, with their labels if `labelled`.
fn mark<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    marks: &[Mark],
    (lo, hi): (f64, f64),
    labelled: bool,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let grey = BLACK.mix(0.45);
    for m in marks {
        let rule = PathElement::new(vec![(m.t, lo), (m.t, hi)], grey.stroke_width(1));
        chart
            .draw_series(std::iter::once(rule))
            .map_err(PlotError::of)?;
        if labelled {
            let font = ("sans-serif", 13).into_font().color(&BLACK.mix(0.75));
            let text = Text::new(format!(" {}", m.label), (m.t, hi), font);
            chart
                .draw_series(std::iter::once(text))
                .map_err(PlotError::of)?;
        }
    }
    Ok(())
}

/// The errors of `agents` agents as their band `b`: shaded from the
/// smallest to the largest, with the largest, the median and the smallest
/// drawn as lines (each thinned to [`POINTS_PER_LINE`]).
fn band_of_agents<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    agents: usize,
    b: &Band,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let upper = floored(decimate(&b.t, &b.max, POINTS_PER_LINE));
    let lower = floored(decimate(&b.t, &b.min, POINTS_PER_LINE));
    let outline: Vec<(f64, f64)> = upper.clone().chain(lower.clone().rev()).collect();
    let shade = palette::colour(0).mix(0.2).filled();
    (chart.draw_series(std::iter::once(Polygon::new(outline, shade)))).map_err(PlotError::of)?;
    let lines = [
        (
            format!("largest of {agents} agents"),
            upper.collect::<Vec<_>>(),
            1,
        ),
        (
            "median".into(),
            floored(decimate(&b.t, &b.median, POINTS_PER_LINE)).collect(),
            2,
        ),
        ("smallest".into(), lower.collect(), 3),
    ];
    for (name, points, k) in lines {
        let style = palette::colour(k).stroke_width(2);
        dashed(chart, points, (style, palette::dash(k)), name)?;
    }
    Ok(())
}

/// `points` with values below the log axes' [`FLOOR`] raised to it.
fn floored(points: Vec<(f64, f64)>) -> impl DoubleEndedIterator<Item = (f64, f64)> + Clone {
    points.into_iter().map(|(t, y)| (t, y.max(FLOOR)))
}

/// A white SVG canvas of `size` px written to `file`, titled `title`
/// (sans-serif 22): the area under the title. Call `present` on it when
/// everything is drawn.
pub(crate) fn canvas<'a>(
    file: &'a Path,
    size: (u32, u32),
    title: &str,
) -> Result<DrawingArea<SVGBackend<'a>, Shift>, PlotError> {
    let root = SVGBackend::new(file, size).into_drawing_area();
    root.fill(&WHITE).map_err(PlotError::of)?;
    root.titled(title, ("sans-serif", 22))
        .map_err(PlotError::of)
}

/// A chart on `area` captioned `caption` (sans-serif 16): 12 px margins,
/// 40 px for the x labels, `y_labels` px for the y labels.
pub(crate) fn chart<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    y_labels: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(area);
    b.margin(12)
        .x_label_area_size(40)
        .y_label_area_size(y_labels)
        .caption(caption, ("sans-serif", 16));
    b
}

/// Draws `points` as a line in `style`, with a 16 px line of it beside
/// `label` in the legend.
pub(crate) fn line<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: ShapeStyle,
    label: impl Into<String>,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    chart
        .draw_series(LineSeries::new(points, style))
        .map_err(PlotError::of)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
    Ok(())
}

/// Draws `points` as a line in `style` with the dash pattern `dash`
/// (`None`: solid; [`palette::dash`]), and 24 px of it beside `label` in
/// the legend.
pub(crate) fn dashed<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    points: impl IntoIterator<Item = (f64, f64)>,
    (style, dash): (ShapeStyle, Option<(u32, u32)>),
    label: impl Into<String>,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let (on, off) = dash.map_or((24, 0), |(on, off)| (on as i32, off as i32));
    let drawn = match dash {
        None => chart.draw_series(LineSeries::new(points, style)),
        Some(_) => {
            let points: Vec<(f64, f64)> = points.into_iter().collect();
            chart.draw_series(DashedLineSeries::new(points, on, off, style))
        }
    };
    drawn
        .map_err(PlotError::of)?
        .label(label)
        .legend(move |(x, y)| {
            plotters::element::DashedPathElement::new(vec![(x, y), (x + 24, y)], on, off, style)
        });
    Ok(())
}

/// Draws `rects`, with a box `width` px wide in `style` beside `label` in
/// the legend.
pub(crate) fn bars<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    rects: impl IntoIterator<Item = Rectangle<(f64, f64)>>,
    label: &str,
    style: ShapeStyle,
    width: i32,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    chart
        .draw_series(rects)
        .map_err(PlotError::of)?
        .label(label)
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + width, y + 5)], style));
    Ok(())
}

/// The legend of `chart`'s labelled series at `position`, on a white,
/// black-bordered box.
pub(crate) fn legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(position)
        .draw()
        .map_err(PlotError::of)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(observer: bool) -> Vec<Series> {
        let t = vec![0.0, 1.0, 2.0];
        let e = vec![1.0, 1e-3, 0.0];
        (1..=2)
            .map(|id| Series {
                id,
                t: t.clone(),
                att: e.clone(),
                angvel: e.clone(),
                obs_att: if observer { e.clone() } else { Vec::new() },
                obs_angvel: if observer { e.clone() } else { Vec::new() },
                torque: Vec::new(),
            })
            .collect()
    }

    fn svg(series: &[Series], aoi: &[LinkSummary]) -> String {
        svg_with(series, aoi, false)
    }

    fn svg_with(series: &[Series], aoi: &[LinkSummary], torque: bool) -> String {
        let tmp = tempfile::tempdir().expect("tempdir");
        let file = tmp.path().join("errors.svg");
        draw(&file, "t", series, aoi, &[], torque).expect("drawn");
        std::fs::read_to_string(file).expect("written")
    }

    #[test]
    fn the_torque_panel_is_drawn_on_request_without_the_last_nan() {
        let mut with = series(true);
        for s in &mut with {
            s.torque = vec![2.0, 0.5, f64::NAN];
        }
        let text = svg_with(&with, &[], true);
        assert!(text.contains(TORQUE.0) && text.contains(OBSERVER_ATT.0));
        assert!(!svg(&with, &[]).contains(TORQUE.0));
        assert_eq!(
            svg(&with, &[]),
            svg(&series(true), &[]),
            "torques drawn only on request"
        );
        let kept = torques(&with);
        assert_eq!(
            (kept[0].t.clone(), kept[0].att.clone()),
            (vec![0.0, 1.0], vec![2.0, 0.5])
        );
    }

    #[test]
    fn the_observer_errors_are_drawn_where_the_scheme_has_them() {
        let with = svg(&series(true), &[]);
        assert!(with.contains(OBSERVER_ATT.0) && with.contains(OBSERVER_ANGVEL.1));
        assert!(!with.contains(AOI));
        let without = svg(&series(false), &[]);
        assert!(!without.contains(OBSERVER_ATT.0) && !without.contains(OBSERVER_ANGVEL.1));
        // The y axes say what they show, in the paper's symbols.
        for (_, y) in [ATT, ANGVEL] {
            assert!(without.contains(y), "no y label {y}");
        }
    }

    fn agents(n: u32, samples: usize) -> Vec<Series> {
        let t: Vec<f64> = (0..samples).map(|k| k as f64 * 0.01).collect();
        (1..=n)
            .map(|id| Series {
                id,
                att: t.iter().map(|t| (-t * f64::from(id)).exp()).collect(),
                angvel: t.iter().map(|t| (-t).exp() / f64::from(id)).collect(),
                t: t.clone(),
                ..Series::default()
            })
            .collect()
    }

    #[test]
    fn a_large_network_is_drawn_as_its_band_whatever_its_size() {
        let few = svg(&agents(EACH_AGENT_UP_TO as u32, 50), &[]);
        assert!(few.contains("agent 16") && !few.contains("largest of"));
        let hundred = svg(&agents(100, 50), &[]);
        let thousands = svg(&agents(5000, 50), &[]);
        assert!(thousands.contains("largest of 5000 agents") && thousands.contains("median"));
        assert!(
            !thousands.contains("agent 1<"),
            "one legend entry per agent"
        );
        let (a, b) = (hundred.len() as f64, thousands.len() as f64);
        assert!(
            (b / a - 1.0).abs() < 0.1,
            "{a} B for 100 agents, {b} B for 5000"
        );
    }

    #[test]
    fn every_agent_has_a_colour_and_dash_of_its_own_as_in_the_palette() {
        let text = svg(&agents(10, 50), &[]);
        // Agents 1–7: the seven colours.
        for k in 0..7 {
            let hex = palette::colour_hex(k);
            assert!(text.contains(hex), "agent {}: {hex} not drawn", k + 1);
        }
        // Agents 8–10 take the colours again, dashed: a dashed line is drawn
        // as many short paths, so the drawing has far more than ten.
        let solid = svg(&agents(7, 50), &[]);
        let paths = |t: &str| t.matches("<polyline").count() + t.matches("<line").count();
        assert!(
            paths(&text) > paths(&solid) + 30,
            "{} {}",
            paths(&text),
            paths(&solid)
        );
    }

    #[test]
    fn a_long_run_is_thinned_to_a_drawing_of_bounded_size() {
        let short = svg(&agents(2, POINTS_PER_LINE), &[]).len() as f64;
        let long = svg(&agents(2, 50 * POINTS_PER_LINE), &[]).len() as f64;
        assert!(
            long < 1.5 * short,
            "{short} B, then {long} B for 50× the samples"
        );
    }

    #[test]
    fn the_age_of_information_is_drawn_per_link() {
        let link = |from, to, mean, max| LinkSummary {
            from,
            to,
            sent: 10,
            delivered: 10,
            lost: 0,
            aoi_mean: mean,
            aoi_max: max,
            aoi_p50: None,
            aoi_p99: None,
            rejected: 0,
        };
        let links = [link(0, 1, 1e-3, 2e-3), link(1, 2, 5e-4, f64::NAN)];
        let text = svg(&series(false), &links);
        assert!(text.contains(AOI), "no panel");
        assert!(
            text.contains("0→1") && text.contains("1→2"),
            "no label per link"
        );
    }
}
