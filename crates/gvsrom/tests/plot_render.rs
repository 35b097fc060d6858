//! Rendering tests of `gvsrom::plot`: every figure kind gives a PNG of the requested size that is not
//! blank and shows its series' colours and its text, and an SVG holding the title and legend labels;
//! bad data gives a `PlotError` naming the figure. `write_look_pngs` (ignored) writes sample figures to
//! /tmp/plot-look/ for a person to look at.

use gvsrom::plot::{
    palette, render, Figure, LineChart, PlotError, Rgb, Scatter2, Scatter3, Series, SeriesStyle,
};
use image::RgbImage;

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// Rod length of the sample strain profiles [m].
const L: f64 = 0.25;

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Bending strain profiles of a tendon-driven rod: a HOM and three ROMs close to it.
fn strain_chart() -> LineChart {
    let x = linspace(0.0, L, 60);
    let hom: Vec<f64> = x
        .iter()
        .map(|&s| 14.0 * (1.0 - s / L).powf(1.3) + 2.0)
        .collect();
    let ae: Vec<f64> = x
        .iter()
        .zip(&hom)
        .map(|(&s, h)| h + 0.15 * (20.0 * s).sin())
        .collect();
    let pod2: Vec<f64> = x.iter().map(|&s| 15.5 - 48.0 * s).collect();
    let pod7: Vec<f64> = x
        .iter()
        .zip(&hom)
        .map(|(&s, h)| h - 0.4 * (40.0 * s).cos())
        .collect();
    LineChart {
        title: "Bending strain along the rod, u = −8 N".into(),
        x_label: "X [m]".into(),
        y_label: "bend-y strain [1/m]".into(),
        series: vec![
            Series::new("HOM", x.clone(), hom, SeriesStyle::Line).with_color(palette::HOM),
            Series::new("AE, 1 DOF", x.clone(), ae, SeriesStyle::Dashed).with_color(palette::AE),
            Series::new("POD, 2 DOFs", x.clone(), pod2, SeriesStyle::Line).with_color(palette::POD),
            Series::new("POD, 7 DOFs", x, pod7, SeriesStyle::Dashed).with_color(palette::POD_ALT),
        ],
        log_y: false,
        equal_aspect: false,
    }
}

/// Centerlines of a rod bent into circular arcs of curvature κ: x = sin(κs)/κ, z = −(1 − cos κs)/κ.
fn rod_chart() -> LineChart {
    let s = linspace(0.0, L, 40);
    let series = [1.0, 3.0, 6.0, 9.0, 12.0]
        .iter()
        .map(|&k: &f64| {
            let x = s.iter().map(|&t| (k * t).sin() / k).collect();
            let z = s.iter().map(|&t| -(1.0 - (k * t).cos()) / k).collect();
            Series::new(format!("u = {:.0} N", -k), x, z, SeriesStyle::Line)
        })
        .collect();
    LineChart {
        title: "Rod configurations (AE ROM)".into(),
        x_label: "x [m]".into(),
        y_label: "z [m]".into(),
        series,
        log_y: false,
        equal_aspect: true,
    }
}

/// Error against DOFs on a log axis, with markers.
fn error_chart() -> LineChart {
    let dof: Vec<f64> = (1..=10).map(f64::from).collect();
    let ae = dof.iter().map(|d| 0.05 * 0.55f64.powf(*d)).collect();
    let pod = dof.iter().map(|d| 0.4 * 0.72f64.powf(*d)).collect();
    LineChart {
        title: "Strain error against DOFs".into(),
        x_label: "DOFs".into(),
        y_label: "MAE / max |ξ| [-]".into(),
        series: vec![
            Series::new("AE", dof.clone(), ae, SeriesStyle::LineMarkers).with_color(palette::AE),
            Series::new("POD", dof, pod, SeriesStyle::LineMarkers).with_color(palette::POD),
        ],
        log_y: true,
        equal_aspect: false,
    }
}

/// Latent codes on a 1-D curve in 2-D, coloured by the tension that produced them.
fn latent2() -> Scatter2 {
    let u = linspace(-30.0, 0.0, 400);
    let x = u.iter().map(|v| (v / 15.0 + 1.0).tanh()).collect();
    let y = u
        .iter()
        .map(|v| 0.6 * (v / 10.0).sin() + 0.02 * v)
        .collect();
    Scatter2 {
        title: "Latent space, 2 DOFs".into(),
        x_label: "q₁".into(),
        y_label: "q₂".into(),
        x,
        y,
        color: Some(u),
        color_label: "tension u [N]".into(),
    }
}

/// Latent codes on a 2-D surface in 3-D, coloured by the third coordinate.
fn latent3() -> Scatter3 {
    let mut points = Vec::new();
    for a in linspace(-1.0, 1.0, 30) {
        for b in linspace(-1.0, 1.0, 30) {
            points.push([a, b, 0.8 * a * b + 0.3 * a * a]);
        }
    }
    let color = points.iter().map(|p| p[2]).collect();
    Scatter3 {
        title: "Latent space, 3 DOFs".into(),
        labels: ["q₁".into(), "q₂".into(), "q₃".into()],
        points,
        color: Some(color),
        color_label: "q₃".into(),
    }
}

fn grid() -> Figure {
    Figure::Grid {
        title: "Tendon-driven manipulator".into(),
        cols: 2,
        panels: vec![
            Figure::Line(strain_chart()),
            Figure::Line(rod_chart()),
            Figure::Scatter2(latent2()),
            Figure::Line(error_chart()),
        ],
    }
}

/// Decodes a rendered PNG after checking its signature and size.
fn decode(png: &[u8], width: u32, height: u32) -> RgbImage {
    assert_eq!(png[..8], PNG_SIGNATURE, "PNG signature");
    let img = image::load_from_memory(png).expect("PNG decodes").to_rgb8();
    assert_eq!(img.dimensions(), (width, height), "PNG size");
    img
}

fn count(img: &RgbImage, pred: impl Fn(&image::Rgb<u8>) -> bool) -> usize {
    img.pixels().filter(|p| pred(p)).count()
}

fn is(c: Rgb) -> impl Fn(&image::Rgb<u8>) -> bool {
    move |p| p.0 == [c.0, c.1, c.2]
}

fn near(c: [u8; 3], tol: i32) -> impl Fn(&image::Rgb<u8>) -> bool {
    move |p| (0..3).all(|k| (p.0[k] as i32 - c[k] as i32).abs() <= tol)
}

/// Whether the SVG has a `<text>` element whose content is `text` (plotters puts it on its own line).
fn svg_has_text(svg: &str, text: &str) -> bool {
    svg.split("<text").skip(1).any(|el| {
        let body = el.split_once('>').map_or("", |(_, rest)| rest);
        body.split("</text>")
            .next()
            .is_some_and(|t| t.trim() == text)
    })
}

fn non_white(p: &image::Rgb<u8>) -> bool {
    p.0 != [255, 255, 255]
}

/// Dark pixels (text, axes) in the rows `rows` of the image.
fn dark_in_rows(img: &RgbImage, rows: std::ops::Range<u32>) -> usize {
    rows.flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 110))
        .count()
}

#[test]
fn strain_chart_renders_lines_legend_and_text_at_requested_size() {
    let out = render(&Figure::Line(strain_chart()), 900, 600).expect("renders");
    let img = decode(&out.png, 900, 600);
    let total = (900 * 600) as usize;
    let ink = count(&img, non_white);
    assert!(
        ink > total / 50 && ink < total / 2,
        "non-white pixels: {ink}"
    );
    for (name, c) in [
        ("HOM", palette::HOM),
        ("AE", palette::AE),
        ("POD", palette::POD),
        ("POD_ALT", palette::POD_ALT),
    ] {
        let n = count(&img, is(c));
        assert!(n > 300, "{name} colour pixels: {n}");
    }
    // The title is text drawn with the embedded font in the top strip.
    assert!(
        dark_in_rows(&img, 0..36) > 150,
        "title pixels: {}",
        dark_in_rows(&img, 0..36)
    );

    assert!(
        out.svg.starts_with("<svg"),
        "SVG head: {}",
        &out.svg[..40.min(out.svg.len())]
    );
    assert!(svg_has_text(
        &out.svg,
        "Bending strain along the rod, u = −8 N"
    ));
    for label in [
        "HOM",
        "AE, 1 DOF",
        "POD, 2 DOFs",
        "POD, 7 DOFs",
        "X [m]",
        "bend-y strain [1/m]",
    ] {
        assert!(svg_has_text(&out.svg, label), "SVG lacks text {label:?}");
    }
    assert!(out.svg.contains("font-family=\"DejaVu Sans, sans-serif\""));
}

#[test]
fn png_title_strip_is_blank_without_title() {
    // The converse of the title check above: the same chart untitled leaves the top rows nearly empty,
    // so the dark pixels there really are the title's glyphs.
    let mut c = strain_chart();
    c.title.clear();
    let img = decode(&render(&Figure::Line(c), 900, 600).unwrap().png, 900, 600);
    assert!(
        dark_in_rows(&img, 0..8) < 20,
        "dark pixels in top rows: {}",
        dark_in_rows(&img, 0..8)
    );
}

#[test]
fn equal_aspect_draws_a_circle_round_on_wide_data() {
    // A unit circle beside a horizontal line 8 units long: with equal scales the circle's pixel bounding
    // box is square (±3 px: line width and rounding); without, the plot stretches it.
    let t = linspace(0.0, std::f64::consts::TAU, 200);
    let circle_color = Rgb(1, 2, 250);
    let chart = |equal_aspect| LineChart {
        title: "circle".into(),
        x_label: "x [m]".into(),
        y_label: "z [m]".into(),
        series: vec![
            Series::new(
                "",
                t.iter().map(|a| a.cos()).collect(),
                t.iter().map(|a| a.sin()).collect(),
                SeriesStyle::Line,
            )
            .with_color(circle_color),
            Series::new("", vec![-4.0, 4.0], vec![0.0, 0.0], SeriesStyle::Line)
                .with_color(Rgb(200, 0, 0)),
        ],
        log_y: false,
        equal_aspect,
    };
    let bbox = |img: &RgbImage| {
        let px: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| is(circle_color)(p))
            .map(|(x, y, _)| (x, y))
            .collect();
        let w = px.iter().map(|p| p.0).max().unwrap() - px.iter().map(|p| p.0).min().unwrap();
        let h = px.iter().map(|p| p.1).max().unwrap() - px.iter().map(|p| p.1).min().unwrap();
        (w as i64, h as i64)
    };
    let (w, h) = bbox(&decode(
        &render(&Figure::Line(chart(true)), 800, 500).unwrap().png,
        800,
        500,
    ));
    assert!((w - h).abs() <= 3, "equal aspect: circle {w}×{h} px");
    let (w, h) = bbox(&decode(
        &render(&Figure::Line(chart(false)), 800, 500).unwrap().png,
        800,
        500,
    ));
    assert!((w - h).abs() > 20, "free aspect: circle {w}×{h} px");
}

#[test]
fn log_chart_skips_non_positive_and_non_finite_points() {
    let mut c = error_chart();
    c.series[0].y[2] = 0.0;
    c.series[0].y[4] = -1.0;
    c.series[1].y[3] = f64::NAN;
    let out = render(&Figure::Line(c), 900, 600).expect("renders with gaps");
    let img = decode(&out.png, 900, 600);
    assert!(count(&img, is(palette::AE)) > 100);
    assert!(count(&img, is(palette::POD)) > 100);
    assert!(svg_has_text(&out.svg, "AE") && svg_has_text(&out.svg, "POD"));
}

#[test]
fn scatter2_colours_points_on_viridis_and_draws_colour_bar() {
    let out = render(&Figure::Scatter2(latent2()), 900, 600).expect("renders");
    let img = decode(&out.png, 900, 600);
    // Both ends of viridis appear (bar and extreme points): dark purple and yellow.
    assert!(count(&img, near([68, 1, 84], 12)) > 50, "viridis low end");
    assert!(
        count(&img, near([253, 231, 37], 12)) > 50,
        "viridis high end"
    );
    for text in ["Latent space, 2 DOFs", "q₁", "q₂", "tension u [N]"] {
        assert!(svg_has_text(&out.svg, text), "SVG lacks {text:?}");
    }
}

#[test]
fn scatter2_without_colour_uses_one_colour_and_no_bar() {
    let mut s = latent2();
    s.color = None;
    let out = render(&Figure::Scatter2(s), 600, 400).expect("renders");
    let img = decode(&out.png, 600, 400);
    assert_eq!(
        count(&img, near([253, 231, 37], 12)),
        0,
        "no viridis without colour"
    );
    assert!(!out.svg.contains("tension u [N]"));
}

#[test]
fn scatter3_renders_points_axes_names_and_colour_bar() {
    let out = render(&Figure::Scatter3(latent3()), 900, 700).expect("renders");
    let img = decode(&out.png, 900, 700);
    assert!(count(&img, non_white) > 900 * 700 / 30);
    assert!(
        count(&img, near([253, 231, 37], 12)) > 50,
        "viridis high end"
    );
    assert!(count(&img, near([68, 1, 84], 12)) > 50, "viridis low end");
    for text in ["Latent space, 3 DOFs", "q₁", "q₂", "q₃"] {
        assert!(svg_has_text(&out.svg, text), "SVG lacks {text:?}");
    }
}

#[test]
fn grid_draws_overall_title_and_every_panel() {
    let out = render(&grid(), 1400, 1000).expect("renders");
    let img = decode(&out.png, 1400, 1000);
    for c in [palette::HOM, palette::AE, palette::POD] {
        assert!(count(&img, is(c)) > 100);
    }
    for text in [
        "Tendon-driven manipulator",
        "Bending strain along the rod, u = −8 N",
        "Rod configurations (AE ROM)",
        "Latent space, 2 DOFs",
        "Strain error against DOFs",
    ] {
        assert!(svg_has_text(&out.svg, text), "SVG lacks {text:?}");
    }
}

#[test]
fn a_long_grid_title_is_shrunk_inside_the_figure() {
    // a tall, narrow grid scales its title font with its area: this caption was 1.2× the width
    // of a 1000 × 1500 figure and ran off both edges; now it keeps a margin on either side
    let title =
        "Static gain −C A⁻¹ B — six-tendon, u = [-10, 0, 0, 0, 0, 0] N, and a longer caption";
    let fig = Figure::Grid {
        title: title.into(),
        cols: 1,
        panels: vec![Figure::Line(strain_chart()), Figure::Line(rod_chart())],
    };
    let out = render(&fig, 1000, 1500).expect("renders");
    let img = decode(&out.png, 1000, 1500);
    assert!(svg_has_text(&out.svg, title), "SVG lacks the title");
    // the title strip: dark text, none in the outer 1 % on either side
    let strip = 0..40;
    assert!(dark_in_rows(&img, strip.clone()) > 500, "no title drawn");
    let edge_ink = strip
        .flat_map(|y| (0..10).chain(990..1000).map(move |x| (x, y)))
        .filter(|&(x, y)| non_white(img.get_pixel(x, y)))
        .count();
    assert_eq!(edge_ink, 0, "the title reaches the figure's edges");
}

#[test]
fn constant_and_single_point_data_render() {
    let c = LineChart {
        title: "flat".into(),
        series: vec![
            Series::new("zero", vec![0.0, 1.0, 2.0], vec![0.0; 3], SeriesStyle::Line),
            Series::new("one point", vec![1.0], vec![0.0], SeriesStyle::Markers),
        ],
        ..Default::default()
    };
    render(&Figure::Line(c), 400, 300).expect("flat data renders");
    let s = Scatter3 {
        title: "one".into(),
        points: vec![[1.0, 1.0, 1.0]],
        color: Some(vec![2.0]),
        ..Default::default()
    };
    render(&Figure::Scatter3(s), 400, 300).expect("single 3-D point renders");
}

fn err(fig: Figure) -> String {
    match render(&fig, 400, 300) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected a PlotError"),
    }
}

#[test]
fn errors_name_the_figure_and_the_series() {
    let empty = LineChart {
        title: "no data here".into(),
        ..Default::default()
    };
    let e = err(Figure::Line(empty));
    assert!(e.contains("no data here"), "{e}");

    let mut c = strain_chart();
    c.title = "mismatch chart".into();
    c.series[2].y.pop();
    let e = err(Figure::Line(c));
    assert!(
        e.contains("mismatch chart")
            && e.contains("POD, 2 DOFs")
            && e.contains("60 x values but 59 y"),
        "{e}"
    );

    let mut c = strain_chart();
    c.title = "all NaN".into();
    for s in &mut c.series {
        s.y.iter_mut().for_each(|v| *v = f64::NAN);
    }
    let e = err(Figure::Line(c));
    assert!(e.contains("all NaN") && e.contains("no finite data"), "{e}");

    let mut c = error_chart();
    c.title = "log of negatives".into();
    c.series
        .iter_mut()
        .for_each(|s| s.y.iter_mut().for_each(|v| *v = -*v));
    let e = err(Figure::Line(c));
    assert!(e.contains("log of negatives") && e.contains("y > 0"), "{e}");

    let mut s = latent2();
    s.color.as_mut().unwrap().pop();
    let e = err(Figure::Scatter2(s));
    assert!(
        e.contains("Latent space, 2 DOFs") && e.contains("tension u [N]"),
        "{e}"
    );

    let s = Scatter3 {
        title: "empty cloud".into(),
        ..Default::default()
    };
    assert!(matches!(
        render(&Figure::Scatter3(s), 400, 300),
        Err(PlotError::Empty { .. })
    ));

    let g = Figure::Grid {
        title: "bad grid".into(),
        cols: 0,
        panels: vec![Figure::Line(strain_chart())],
    };
    assert!(err(g).contains("bad grid"));

    // An error inside a panel names the panel.
    let mut bad = strain_chart();
    bad.title = "inner panel".into();
    bad.series[0].x.clear();
    let g = Figure::Grid {
        title: "outer".into(),
        cols: 2,
        panels: vec![Figure::Line(rod_chart()), Figure::Line(bad)],
    };
    let e = err(g);
    assert!(e.contains("inner panel") && e.contains("HOM"), "{e}");

    let e = render(&Figure::Line(strain_chart()), 0, 600)
        .unwrap_err()
        .to_string();
    assert!(e.contains("Bending strain") && e.contains("0×600"), "{e}");
}

/// Writes the sample figures to /tmp/plot-look/*.png for viewing:
/// `cargo test -p gvsrom --test plot_render -- --ignored write_look_pngs`.
#[test]
#[ignore]
fn write_look_pngs() {
    let dir = std::path::Path::new("/tmp/plot-look");
    std::fs::create_dir_all(dir).unwrap();
    let figs = [
        ("strain", Figure::Line(strain_chart()), 900, 600),
        ("rods", Figure::Line(rod_chart()), 900, 600),
        ("error-log", Figure::Line(error_chart()), 900, 600),
        ("latent2", Figure::Scatter2(latent2()), 900, 600),
        ("latent3", Figure::Scatter3(latent3()), 900, 700),
        ("grid", grid(), 1400, 1000),
        (
            "grid-3d",
            Figure::Grid {
                title: String::new(),
                cols: 2,
                panels: vec![Figure::Scatter3(latent3()), Figure::Line(strain_chart())],
            },
            1400,
            560,
        ),
    ];
    for (name, fig, w, h) in figs {
        let out = render(&fig, w, h).unwrap();
        std::fs::write(dir.join(format!("{name}.png")), &out.png).unwrap();
        std::fs::write(dir.join(format!("{name}.svg")), &out.svg).unwrap();
    }
}

#[test]
fn extreme_values_and_tiny_sizes_do_not_panic_or_hang() {
    // Data spanning the whole f64 range, subnormals and infinities, at the smallest accepted size and
    // at a normal one: each render returns (Ok or a PlotError) quickly.
    let weird = vec![
        vec![0.0, f64::MAX],
        vec![-f64::MAX, f64::MAX],
        vec![1e-320, 2e-320],
        vec![f64::INFINITY, 1.0, f64::NEG_INFINITY, 2.0],
        vec![1e300, -1e300, 0.0],
    ];
    let start = std::time::Instant::now();
    for (w, h) in [(64, 64), (300, 200)] {
        for ys in &weird {
            let x: Vec<f64> = (0..ys.len()).map(|i| i as f64).collect();
            for (log_y, equal_aspect) in [(false, false), (true, false), (false, true)] {
                let c = LineChart {
                    title: "weird".into(),
                    x_label: "x".into(),
                    y_label: "y".into(),
                    series: vec![Series::new(
                        "s",
                        x.clone(),
                        ys.clone(),
                        SeriesStyle::LineMarkers,
                    )],
                    log_y,
                    equal_aspect,
                };
                let _ = render(&Figure::Line(c), w, h);
            }
            let s = Scatter2 {
                title: "weird".into(),
                x: x.clone(),
                y: ys.clone(),
                color: Some(ys.clone()),
                ..Default::default()
            };
            let _ = render(&Figure::Scatter2(s), w, h);
            let points = ys.iter().map(|&v| [v, 1.0, v]).collect();
            let s = Scatter3 {
                title: "weird".into(),
                points,
                color: Some(ys.clone()),
                ..Default::default()
            };
            let _ = render(&Figure::Scatter3(s), w, h);
        }
        let _ = render(&grid(), w, h);
    }
    assert!(
        start.elapsed().as_secs_f64() < 20.0,
        "took {:?}",
        start.elapsed()
    );
}

/// A helix and its axis as 3-D lines, equal scales.
fn line3() -> gvsrom::plot::Line3 {
    use gvsrom::plot::Series3;
    let s = linspace(0.0, 1.0, 80);
    let helix = s
        .iter()
        .map(|&t| [0.05 * (12.0 * t).cos(), 0.05 * (12.0 * t).sin(), 0.2 * t])
        .collect();
    gvsrom::plot::Line3 {
        title: "Helix".into(),
        labels: ["x [m]".into(), "y [m]".into(), "z [m]".into()],
        series: vec![
            Series3::new("helix", helix, SeriesStyle::Line).with_color(palette::HOM),
            Series3::new(
                "axis",
                vec![[0.0, 0.0, 0.0], [0.0, 0.0, 0.2]],
                SeriesStyle::Dashed,
            )
            .with_color(palette::POD),
            Series3::new(
                "box",
                vec![[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]],
                SeriesStyle::Bounds,
            ),
        ],
        equal_aspect: true,
    }
}

#[test]
fn line3_draws_its_series_legend_and_axis_names_but_not_bounds() {
    let out = render(&Figure::Line3(line3()), 900, 700).unwrap();
    let img = decode(&out.png, 900, 700);
    assert!(count(&img, is(palette::HOM)) > 100, "helix not drawn");
    assert!(count(&img, is(palette::POD)) > 20, "axis not drawn");
    for text in ["Helix", "helix", "axis", "x [m]", "z [m]"] {
        assert!(svg_has_text(&out.svg, text), "SVG lacks {text:?}");
    }
    // a Bounds series has no legend entry; it widens the box to ±1 m
    assert!(!svg_has_text(&out.svg, "box"));
    assert!(svg_has_text(&out.svg, "-1.0") || svg_has_text(&out.svg, "-1"));
}

#[test]
fn gif_animation_has_one_frame_per_figure_and_refuses_no_frames() {
    use image::AnimationDecoder;
    let frames: Vec<Figure> = (0..3)
        .map(|k| {
            let mut c = rod_chart();
            c.series.truncate(k + 1);
            Figure::Line(c)
        })
        .collect();
    let gif = gvsrom::plot::animation::render_gif(&frames, 320, 240, 100).unwrap();
    let dec = image::codecs::gif::GifDecoder::new(&gif[..]).unwrap();
    let decoded = dec.into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), 3);
    assert_eq!(decoded[0].buffer().dimensions(), (320, 240));
    assert_ne!(decoded[0].buffer(), decoded[2].buffer());
    let err = gvsrom::plot::animation::render_gif(&[], 320, 240, 100).unwrap_err();
    assert!(matches!(err, PlotError::Empty { .. }), "{err}");
}

#[test]
fn gif_of_a_rod_animation_stays_small_enough_to_commit() {
    use gvsrom::plot::{Line3, Series3};
    // The layout of `gvsrom plot`'s rod_animation.gif: 36 frames of 960 × 440, the rod in 3-D and
    // from the side with the tip's dashed path so far, on the axes of the whole run.
    let tip = |t: f64| {
        let k = 4.0 + 3.0 * (1.3 * t).sin();
        let phi = 0.9 * t;
        let (x, z) = ((k * L).sin() / k, -(1.0 - (k * L).cos()) / k);
        (k, phi, [x * phi.cos(), x * phi.sin(), z])
    };
    let times = linspace(0.0, 10.0, 36);
    let frames: Vec<Figure> = times
        .iter()
        .map(|&t| {
            let (k, phi, end) = tip(t);
            let rod: Vec<[f64; 3]> = linspace(0.0, L, 50)
                .iter()
                .map(|&s| {
                    let x = (k * s).sin() / k;
                    [x * phi.cos(), x * phi.sin(), -(1.0 - (k * s).cos()) / k]
                })
                .collect();
            let trace = linspace(0.0, t, 200).iter().map(|&u| tip(u).2).collect();
            let bounds = vec![[-L, -L, -L], [L, L, 0.05]];
            let s3 = vec![
                Series3::new("", trace, SeriesStyle::Dashed).with_color(palette::EXTRA[6]),
                Series3::new("", rod, SeriesStyle::Line).with_color(palette::HOM),
                Series3::new("", vec![end], SeriesStyle::Markers).with_color(palette::POD),
                Series3::new("", bounds, SeriesStyle::Bounds),
            ];
            let side: Vec<Series> = s3
                .iter()
                .map(|s| {
                    let x = s.points.iter().map(|p| p[0]).collect();
                    let z = s.points.iter().map(|p| p[2]).collect();
                    let mut c = Series::new("", x, z, s.style);
                    c.color = s.color;
                    c
                })
                .collect();
            Figure::Grid {
                title: format!("rod — t = {t:.3} s"),
                cols: 2,
                panels: vec![
                    Figure::Line3(Line3 {
                        title: String::new(),
                        labels: ["x [m]".into(), "y [m]".into(), "z [m]".into()],
                        series: s3,
                        equal_aspect: true,
                    }),
                    Figure::Line(LineChart {
                        x_label: "x [m]".into(),
                        y_label: "z [m]".into(),
                        series: side,
                        equal_aspect: true,
                        ..Default::default()
                    }),
                ],
            }
        })
        .collect();
    let gif = gvsrom::plot::animation::render_gif(&frames, 960, 440, 280).unwrap();
    // 300 kB is what a README figure may weigh; a frame per file with a palette of its own made
    // ~1 MB of this (1.05 MB for `gvsrom plot` of a 10 s six-tendon run, now 118 kB).
    assert!(gif.len() < 300_000, "{} bytes", gif.len());
    let dec = image::codecs::gif::GifDecoder::new(&gif[..]).unwrap();
    use image::AnimationDecoder;
    let decoded = dec.into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), 36);
    // the last frame, composed over the earlier ones, shows the rod and the tip marker in full colour
    let last = decoded[35].buffer();
    let n = |c: Rgb| {
        last.pixels()
            .filter(|p| p.0[..3] == [c.0, c.1, c.2])
            .count()
    };
    assert!(
        n(palette::HOM) > 100 && n(palette::POD) > 10,
        "rod or tip lost"
    );
}
