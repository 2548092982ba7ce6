//! `tdex report` end to end on the tiny drum: the SVGs are valid XML with drawn elements,
//! every Markdown link resolves, the HTML references the plots, the tables hold numbers, and
//! the same inputs give the same bytes. Without a DEM reference the report is the prediction
//! alone, over every extrapolated period.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use tdex_format::ExtrapolationReader;

/// The plots of a split bed (no conducting wall) with a DEM reference.
const PLOTS: [&str; 9] = [
    "bed_mean.svg",
    "means.svg",
    "spread.svg",
    "lacey.svg",
    "fields.svg",
    "eps_rel.svg",
    "error_vs_speedup.svg",
    "duration_cdf.svg",
    "field.svg",
];

/// The tiny drum with its mantle held at 350 K (as tests/cli_record.rs).
fn heated_case() -> String {
    TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    )
}

/// Records `case_text` for τ = 0.1 s without a reference, extrapolates `periods` and reports
/// into `dir/report`; returns the extrapolation's path and the report directory.
fn report_without_reference(
    dir: &std::path::Path,
    case_text: &str,
    periods: u32,
) -> (std::path::PathBuf, std::path::PathBuf) {
    let case = dir.join("case.toml");
    std::fs::write(&case, case_text).unwrap();
    let run = dir.join("run.mcap");
    let extra = dir.join("extra.mcap");
    let out = dir.join("report");
    let (case_s, run_s, extra_s, out_s) = (
        case.to_str().unwrap(),
        run.to_str().unwrap(),
        extra.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    tdex_ok(&["record", case_s, "-o", run_s, "--tau", "0.1"]);
    let periods = periods.to_string();
    tdex_ok(&["extrapolate", run_s, "--periods", &periods, "-o", extra_s]);
    tdex_ok(&["report", run_s, extra_s, "-o", out_s]);
    (extra, out)
}

/// The number of points of each data line of an SVG (the `<polyline>`s plotters writes for
/// a line series), leaving out those of two points (legend samples, dashes, markers'
/// guide lines), sorted.
fn data_lines(name: &str, bytes: &[u8]) -> Vec<usize> {
    let text = std::str::from_utf8(bytes).unwrap();
    let doc = roxmltree::Document::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut lines: Vec<usize> = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .map(|n| {
            n.attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .count()
        })
        .filter(|&n| n > 2)
        .collect();
    lines.sort();
    lines
}

/// The targets of the Markdown links and images `[..](target)`.
fn markdown_links(md: &str) -> Vec<String> {
    md.match_indices("](")
        .map(|(i, _)| {
            let rest = &md[i + 2..];
            rest[..rest.find(')').expect("a link is closed")].to_string()
        })
        .collect()
}

/// The numeric cells of the Markdown table row whose first cell is `label`.
fn table_row(md: &str, label: &str) -> Vec<f64> {
    let line = md
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")))
        .unwrap_or_else(|| panic!("no table row '{label}' in\n{md}"));
    line.trim_matches('|')
        .split('|')
        .skip(1)
        .map(|c| {
            c.trim()
                .parse::<f64>()
                .unwrap_or_else(|_| panic!("'{c}' in row '{label}' is not a number"))
        })
        .collect()
}

fn check_svg(name: &str, bytes: &[u8]) {
    let text = std::str::from_utf8(bytes).unwrap_or_else(|e| panic!("{name}: not UTF-8: {e}"));
    let doc = roxmltree::Document::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg", "{name}: root element");
    for dim in ["width", "height"] {
        let v: f64 = root
            .attribute(dim)
            .unwrap_or_else(|| panic!("{name}: no {dim}"))
            .parse()
            .unwrap();
        assert!(v > 0.0, "{name}: {dim} = {v}");
    }
    let count = |tags: &[&str]| {
        root.descendants()
            .filter(|n| tags.contains(&n.tag_name().name()))
            .count()
    };
    assert!(
        count(&["path", "line", "circle", "polyline"]) > 0,
        "{name}: nothing drawn"
    );
    assert!(count(&["text"]) >= 3, "{name}: no axis labels");
}

#[test]
fn report_writes_valid_svgs_and_resolving_links() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let run = dir.path().join("run.mcap");
    let extra = dir.path().join("extra.mcap");
    let out = dir.path().join("report");
    let (case_s, run_s, extra_s, out_s) = (
        case.to_str().unwrap(),
        run.to_str().unwrap(),
        extra.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    tdex_ok(&[
        "record",
        case_s,
        "-o",
        run_s,
        "--tau-rev",
        "0.25",
        "--reference",
        "2",
    ]);
    tdex_ok(&["extrapolate", run_s, "--periods", "2", "-o", extra_s]);
    let stdout = tdex_ok(&["report", run_s, extra_s, "-o", out_s, "--cells", "20"]);

    let written = files(&out);
    let mut expected: Vec<String> = PLOTS.iter().map(|s| s.to_string()).collect();
    expected.extend(["report.md".into(), "report.html".into()]);
    expected.sort();
    assert_eq!(
        written.keys().cloned().collect::<Vec<_>>(),
        expected,
        "exactly the report's files, no temporary ones"
    );
    for name in &expected {
        assert!(
            stdout.lines().any(|l| l.ends_with(name.as_str())),
            "stdout does not list {name}: {stdout}"
        );
    }
    for plot in PLOTS {
        check_svg(plot, &written[plot]);
    }

    // Every Markdown link names a file of the report, and every plot is linked.
    let md = String::from_utf8(written["report.md"].clone()).unwrap();
    let links = markdown_links(&md);
    for target in &links {
        assert!(
            out.join(target).is_file(),
            "report.md links to '{target}', which is not in {}",
            out.display()
        );
    }
    for plot in PLOTS {
        assert!(
            links.iter().any(|l| l == plot),
            "report.md does not link {plot}"
        );
    }

    // The HTML is well-formed and shows the same plots.
    let html = String::from_utf8(written["report.html"].clone()).unwrap();
    let doc = roxmltree::Document::parse_with_options(
        &html,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .expect("report.html is well-formed");
    let images: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("img"))
        .filter_map(|n| n.attribute("src"))
        .collect();
    for plot in PLOTS {
        assert!(
            images.contains(&plot),
            "report.html shows no {plot}: {images:?}"
        );
    }
    assert!(!html.contains("<script"));

    // The tables hold numbers: the errors at t_2 and t_3, the costs for 100 τ.
    assert!(md.contains("| Extrapolation step | t_2 | t_3 |"), "{md}");
    let eps_abs = table_row(&md, "ε_abs (K)");
    assert_eq!(eps_abs.len(), 2);
    assert!(eps_abs.iter().all(|e| e.is_finite() && *e >= 0.0));
    assert_eq!(table_row(&md, "ε_rel (%)").len(), 2);
    let until_t1 = table_row(&md, "Until t1 (s)");
    assert!(
        until_t1[0] > 0.0 && until_t1[0] == until_t1[1],
        "{until_t1:?}"
    );
    assert_eq!(table_row(&md, "Pairing (s)")[0], 0.0);
    assert_eq!(table_row(&md, "Collision file (s)")[0], 0.0);
    let reading = table_row(&md, "Reading the table (s)");
    assert!(reading[0] == 0.0 && reading[1] >= 0.0, "{reading:?}");
    let per_tau = table_row(&md, "For one τ (s)");
    assert!(per_tau.iter().all(|s| *s > 0.0), "{per_tau:?}");
    let total = table_row(&md, "Total for 100 τ (s)");
    assert_eq!(total.len(), 2);
    assert!(
        total[0] > until_t1[0] && total[1] > until_t1[1],
        "{total:?}"
    );
    assert!(md.contains("Speedup: **"), "{md}");
    assert!(md.contains("thread(s)"), "{md}");

    // Same inputs, same bytes: a second report over the first one.
    tdex_ok(&["report", run_s, extra_s, "-o", out_s, "--cells", "20"]);
    assert_eq!(files(&out), written, "the report is not deterministic");
}

#[test]
fn report_refuses_a_file_as_output_directory() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not_a_dir");
    std::fs::write(&file, "x").unwrap();
    let o = run_tdex(&[
        "report",
        "run.mcap",
        "extra.mcap",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("not_a_dir"), "{err}");
}

#[test]
fn a_heated_wall_extrapolated_200_periods_without_reference_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let (extra, out) = report_without_reference(dir.path(), &heated_case(), 200);
    let written = files(&out);
    // the heated tiny case is also split hot/cold: group means and mixing too; no error,
    // speedup or DEM field plot without a reference
    let mut expected: Vec<String> = [
        "bed_mean.svg",
        "means.svg",
        "wall_heat.svg",
        "spread.svg",
        "lacey.svg",
        "fields.svg",
        "duration_cdf.svg",
        "report.md",
        "report.html",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    expected.sort();
    assert_eq!(written.keys().cloned().collect::<Vec<_>>(), expected);
    for (name, bytes) in &written {
        if name.ends_with(".svg") {
            check_svg(name, bytes);
        }
    }

    // every extrapolated period is drawn: the bed mean at t1 and at the 200 extrapolated
    // t_k (201 points); the walls' heat per period (200) and since t1 (201, from 0 at t1)
    assert_eq!(
        data_lines("bed_mean.svg", &written["bed_mean.svg"]),
        vec![201]
    );
    assert_eq!(
        data_lines("wall_heat.svg", &written["wall_heat.svg"]),
        vec![200, 201]
    );

    // the summary's bed mean is the volume-weighted mean of the last extrapolated snapshot
    let md = String::from_utf8(written["report.md"].clone()).unwrap();
    let first = md.lines().find(|l| l.starts_with("- ")).expect("a summary");
    let prefix = "- After 200 periods (20 s) the bed mean is ";
    assert!(first.starts_with(prefix), "{first}");
    let printed = first[prefix.len()..]
        .split(" K")
        .next()
        .unwrap()
        .to_string();
    let value: f64 = printed.parse().unwrap();
    let decimals = printed.split_once('.').map_or(0, |(_, d)| d.len());
    let snaps = ExtrapolationReader::open(&extra)
        .unwrap()
        .snapshots()
        .unwrap();
    assert_eq!(snaps.len(), 201);
    let last = snaps.last().unwrap();
    assert_eq!(last.index, 201);
    let (heat, volume) = last
        .radius
        .iter()
        .zip(&last.temp)
        .fold((0.0, 0.0), |(h, v), (r, t)| {
            (h + r.powi(3) * t, v + r.powi(3))
        });
    let bed = heat / volume;
    assert!(
        (value - bed).abs() <= 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9,
        "summary says {printed} K, the file's last snapshot {bed} K"
    );
    assert!(bed > 30.0 && bed < 350.0, "the wall heats the bed: {bed}");
    assert!(first.contains("of the way from its start"), "{first}");
    assert!(first.contains("to the wall temperature (350 K)"), "{first}");
    assert!(
        md.contains("No DEM reference was recorded, so nothing is judged"),
        "{md}"
    );
    assert!(!md.contains("Trust:"), "{md}");
    // the links resolve
    for target in markdown_links(&md) {
        assert!(out.join(&target).is_file(), "report.md links to '{target}'");
    }
}

#[test]
fn a_split_bed_without_reference_gets_group_means_and_mixing() {
    let dir = tempfile::tempdir().unwrap();
    let (_, out) = report_without_reference(dir.path(), TINY_CASE, 12);
    let written = files(&out);
    for plot in [
        "means.svg",
        "lacey.svg",
        "bed_mean.svg",
        "spread.svg",
        "fields.svg",
    ] {
        let bytes = written
            .get(plot)
            .unwrap_or_else(|| panic!("no {plot} in {:?}", written.keys()));
        check_svg(plot, bytes);
    }
    // adiabatic walls: no wall heat; no reference: no errors
    for absent in [
        "wall_heat.svg",
        "eps_rel.svg",
        "error_vs_speedup.svg",
        "field.svg",
    ] {
        assert!(!written.contains_key(absent), "{absent} written");
    }
    // hot and cold group means at t1 and the 12 extrapolated t_k, and the Lacey index at each
    assert_eq!(data_lines("means.svg", &written["means.svg"]), vec![13, 13]);
    assert_eq!(data_lines("lacey.svg", &written["lacey.svg"]), vec![13]);
    let md = String::from_utf8(written["report.md"].clone()).unwrap();
    let summary: Vec<&str> = md.lines().filter(|l| l.starts_with("- ")).take(3).collect();
    assert!(summary[0].contains("no wall conducts"), "{summary:?}");
    assert!(
        summary[1].contains("The initially hot and cold particles are")
            && summary[1].contains("Lacey index"),
        "{summary:?}"
    );
    assert!(
        summary[2].starts_with("- No DEM reference was recorded"),
        "{summary:?}"
    );
}
