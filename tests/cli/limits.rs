//! The CLI's limits: huge and far coordinates, absurd sizes, line numbers, nothing
//! left behind after a refusal, numeric options validated alike, scenes at any scale.

use super::*;

/// Class 1: coordinates near the limits of f64 are refused with file and line, and
/// the largest accepted ones give finite distances on every backend.
#[test]
fn huge_coordinates_are_refused_or_finite() {
    let dir = tempfile::tempdir().unwrap();
    let (_, _, q) = setup();
    let huge = write(dir.path(), "huge.csv", "0,0,0\n\n1e300,-1e300,1e160\n");
    fails(
        dir.path(),
        &["--photons", huge.to_str().unwrap(), "--queries", &q],
        "huge.csv:3: coordinates must lie within ±1e150",
    );
    let big = write(
        dir.path(),
        "big.csv",
        "1e150,-1e150,1e150\n-1e150,1e150,-1e150\n0,0,0\n1e-300,5,-7\n",
    );
    let qs = write(dir.path(), "q.csv", "1e150,1e150,1e150\n-3,2,1\n");
    for backend in ["float", "sw", "rtl"] {
        let out = dir.path().join(format!("{backend}.csv"));
        let lines = gather_lines(
            &[
                "--photons",
                big.to_str().unwrap(),
                "--queries",
                qs.to_str().unwrap(),
                "--k",
                "4",
                "--backend",
                backend,
            ],
            &out,
        );
        assert_eq!(lines.len(), 1 + 2 * 4, "{backend}");
        for l in &lines[1..] {
            let d: f64 = l.rsplit(',').next().unwrap().parse().unwrap();
            assert!(d.is_finite() && d >= 0.0, "{backend}: {l}");
        }
    }
}

/// Class 2: the grid covers the photons alone, so a far query changes no other
/// query's answer, and its own answer is exact (photons on the unit grid, step 1).
#[test]
fn a_far_query_changes_no_other_answer() {
    let dir = tempfile::tempdir().unwrap();
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(13);
    let photons: Vec<[f64; 3]> = (0..300)
        .map(|i| match i {
            0 => [0.0, 0.0, 0.0],
            1 => [1023.0, 0.0, 0.0],
            _ => [0; 3].map(|_| r.gen_range(0..1024) as f64),
        })
        .collect();
    let p = write(dir.path(), "p.csv", &points_csv(&photons, false));
    let near: Vec<[f64; 3]> = (0..10)
        .map(|_| [0; 3].map(|_| r.gen_range(0..1024) as f64))
        .collect();
    let mut with_far = near.clone();
    with_far.insert(4, [5000.0, -700.0, 1e6]);
    let q1 = write(dir.path(), "q1.csv", &points_csv(&near, false));
    let q2 = write(dir.path(), "q2.csv", &points_csv(&with_far, false));
    for backend in ["float", "sw", "rtl"] {
        for metric in ["l2", "l1"] {
            let args = |q: &Path| {
                vec![
                    "--photons".to_string(),
                    p.display().to_string(),
                    "--queries".to_string(),
                    q.display().to_string(),
                    "--k".to_string(),
                    "5".to_string(),
                    "--metric".to_string(),
                    metric.to_string(),
                    "--backend".to_string(),
                    backend.to_string(),
                ]
            };
            let run = |q: &Path, name: &str| {
                let a = args(q);
                let a: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
                gather_lines(&a, &dir.path().join(name))
            };
            let a = run(&q1, "a.csv");
            let b = run(&q2, "b.csv");
            // Every line of the near queries is unchanged (query 4 and later shift by one).
            let renumber = |l: &String| {
                let (q, rest) = l.split_once(',').unwrap();
                let q: usize = q.parse().unwrap();
                (q, rest.to_string())
            };
            let b_near: Vec<(usize, String)> = b[1..]
                .iter()
                .map(renumber)
                .filter(|(q, _)| *q != 4)
                .map(|(q, rest)| (if q > 4 { q - 1 } else { q }, rest))
                .collect();
            let a_all: Vec<(usize, String)> = a[1..].iter().map(renumber).collect();
            assert_eq!(a_all, b_near, "{backend} {metric}");
            // The far query's own answer: exact distances (step 1 on this map).
            let truth = true_dists(metric, &photons, &with_far[4]);
            let got: Vec<f64> = b[1..]
                .iter()
                .map(renumber)
                .filter(|(q, _)| *q == 4)
                .map(|(_, rest)| rest.rsplit(',').next().unwrap().parse().unwrap())
                .collect();
            assert_eq!(got.len(), 5);
            for (g, t) in got.iter().zip(&truth) {
                assert!((g - t).abs() <= 1e-9 * t, "{backend} {metric}: {g} vs {t}");
            }
        }
    }
    // Beyond 2^62 grid steps from the photons: refused, naming the query's line.
    let q3 = write(dir.path(), "q3.csv", "1,1,1\n\n1e140,0,0\n");
    fails(
        dir.path(),
        &[
            "--photons",
            p.to_str().unwrap(),
            "--queries",
            q3.to_str().unwrap(),
        ],
        "q3.csv:3: the query at",
    );
}

/// Class 3: what cannot be served is refused before any work or allocation (exit 2,
/// not an allocator abort), and the output is checked before photons are traced.
#[test]
fn absurd_sizes_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png").display().to_string();
    let render = |extra: &[&str]| cmdline(&["render", "--out", &out], extra);
    refused(
        dir.path(),
        &render(&["--photons", "100000000000"]),
        "--photons must be in 1..=",
    );
    refused(
        dir.path(),
        &render(&["--size", "16384x16384", "--spp", "4000000"]),
        "the limit is 8 GiB",
    );
    refused(
        dir.path(),
        &render(&["--size", "4096x4096", "--k", "1000000000000"]),
        "the limit is 8 GiB",
    );
    refused(
        dir.path(),
        &render(&["--photons", "4000000000", "--capacity", "1000000000000"]),
        "--capacity 1000000000000 photons could need",
    );
    refused(
        dir.path(),
        &render(&["--photons", "4000000000", "--capacity", "1000"]),
        "store more than --capacity 1000 photons (stopped early)",
    );
    // The output directory is checked before the (here hopeless) trace starts.
    let missing = dir
        .path()
        .join("no-such-dir")
        .join("r.png")
        .display()
        .to_string();
    refused(
        dir.path(),
        &strings(&[
            "render",
            "--out",
            &missing,
            "--photons",
            "1000",
            "--capacity",
            "10",
        ]),
        "cannot write in its directory",
    );
    let (d2, p, q) = setup();
    let many: String = (0..10_000).map(|i| format!("{i},0,0\n")).collect();
    let many = write(d2.path(), "many.csv", &many);
    let queries: String = "0.5,0.5,0.5\n".repeat(200_000);
    let queries = write(d2.path(), "queries.csv", &queries);
    fails(
        d2.path(),
        &[
            "--photons",
            many.to_str().unwrap(),
            "--queries",
            queries.to_str().unwrap(),
            "--k",
            "1000000",
        ],
        "the limit is 8 GiB",
    );
    let _ = (p, q);
}

/// Class 4: errors name the file's real line after blank lines and with CRLF or
/// CR-only line endings.
#[test]
fn line_numbers_are_the_files() {
    let (dir, _, q) = setup();
    for (name, text) in [
        ("lf.csv", "1,2,3\n\n\n4,5,6\nbad\n"),
        ("crlf.csv", "1,2,3\r\n\r\n\r\n4,5,6\r\nbad\r\n"),
        ("cr.csv", "1,2,3\r\r\r4,5,6\rbad\r"),
        ("mixed.csv", "x,y,z\r\n1,2,3\n\r4,5,6\rbad\n"),
    ] {
        let f = write(dir.path(), name, text);
        fails(
            dir.path(),
            &["--photons", f.to_str().unwrap(), "--queries", &q],
            &format!("{name}:5: expected three numbers x,y,z, got 'bad'"),
        );
    }
}

/// Class 5: a failed run leaves nothing (not even the VCD), an output that is an
/// input is refused, a device is written in place, a symlink is written through and
/// stays a link, and a user's `out.csv.tmp` is never touched.
#[test]
fn nothing_is_left_behind() {
    let (dir, p, q) = setup();
    let out = dir.path().join("out.csv");
    // The input itself as output: refused, the input unchanged.
    let before = std::fs::read(&p).unwrap();
    refused(
        dir.path(),
        &strings(&["gather", "--photons", &p, "--queries", &q, "--out", &p]),
        "is also an input",
    );
    assert_eq!(std::fs::read(&p).unwrap(), before);
    // The simulation ran and wrote its VCD, then the output failed (/dev/full): no VCD.
    let vcd = dir.path().join("wave.vcd").display().to_string();
    refused(
        dir.path(),
        &strings(&[
            "gather",
            "--photons",
            &p,
            "--queries",
            &q,
            "--backend",
            "rtl",
            "--vcd",
            &vcd,
            "--out",
            "/dev/full",
        ]),
        "cannot write",
    );
    // The same through the environment variable.
    let before = listing(dir.path());
    let assert = bin()
        .env("PHOTON_FPGA_VCD", &vcd)
        .args([
            "gather",
            "--photons",
            &p,
            "--queries",
            &q,
            "--backend",
            "rtl",
        ])
        .args(["--out", "/dev/full"])
        .assert()
        .code(2);
    assert!(String::from_utf8_lossy(&assert.get_output().stderr).contains("cannot write"));
    assert_eq!(listing(dir.path()), before);
    // A successful rtl run keeps its VCD.
    bin()
        .args([
            "gather",
            "--photons",
            &p,
            "--queries",
            &q,
            "--backend",
            "rtl",
        ])
        .args(["--vcd", &vcd, "--out"])
        .arg(&out)
        .assert()
        .success();
    assert!(std::fs::read_to_string(&vcd)
        .unwrap()
        .contains("$enddefinitions"));
    // A device is written in place.
    let assert = bin()
        .args([
            "gather",
            "--photons",
            &p,
            "--queries",
            &q,
            "--out",
            "/dev/stdout",
        ])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    assert!(
        stdout.starts_with("query,rank,photon,distance\n0,0,"),
        "{stdout}"
    );
    // A symlink is written through and stays a link; a user's .tmp file stays.
    let target = dir.path().join("target.csv");
    std::fs::write(
        &target,
        "old content that is longer than the new one ........\n".repeat(9),
    )
    .unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let user_tmp = dir.path().join("link.csv.tmp");
    std::fs::write(&user_tmp, "mine").unwrap();
    bin()
        .args(["gather", "--photons", &p, "--queries", &q, "--out"])
        .arg(&link)
        .assert()
        .success();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::read_to_string(&target).unwrap(),
        std::fs::read_to_string(&out).unwrap()
    );
    assert_eq!(std::fs::read_to_string(&user_tmp).unwrap(), "mine");
    // A new output gets the permissions of any new file (not a temporary file's 0600).
    use std::os::unix::fs::PermissionsExt;
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    let plain = dir.path().join("plain");
    std::fs::write(&plain, "").unwrap();
    let plain_mode = std::fs::metadata(&plain).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, plain_mode, "output mode {mode:o}");
}

/// Class 6: every numeric option is validated alike, and an option the backend
/// would ignore is an error.
#[test]
fn numeric_options_are_validated_alike() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png").display().to_string();
    for e in ["nan", "inf", "-1", "0"] {
        refused(
            dir.path(),
            &strings(&["render", "--out", &out, "--exposure", e]),
            "--exposure must be a finite number > 0",
        );
    }
    refused(
        dir.path(),
        &strings(&["render", "--out", &out, "--spp", "0"]),
        "--spp must be at least 1, got 0",
    );
    refused(
        dir.path(),
        &strings(&["render", "--out", &out, "--photons", "0"]),
        "--photons must be in 1..=",
    );
    for r in ["nan", "inf", "-0.5"] {
        refused(
            dir.path(),
            &strings(&["render", "--out", &out, "--radius", r]),
            "--radius must be a finite number >= 0",
        );
    }
    let (d, p, q) = setup();
    fails(
        d.path(),
        &[
            "--photons",
            &p,
            "--queries",
            &q,
            "--backend",
            "float",
            "--bits",
            "12",
        ],
        "--bits sets the grid of the quantized backends",
    );
}

/// Class 7: the same scene scaled by 1e-6, 1e-4, 1e6 or 1e12 renders (the same image up to
/// f32 rounding); scaled by 1e30 or 1e-30 it is refused with the real cause.
#[test]
fn scenes_at_any_scale() {
    let dir = tempfile::tempdir().unwrap();
    let src = include_str!("../../scenes/cornell.toml");
    let scaled = |f: f64| -> String {
        src.lines()
            .map(|line| {
                let t = line.trim_start();
                let key = t.split('=').next().unwrap_or("").trim();
                let vec_keys = [
                    "position", "look_at", "corner", "edge_u", "edge_v", "center",
                ];
                if vec_keys.contains(&key) || key == "power" {
                    let g = if key == "power" { f * f } else { f };
                    let inside = &t[t.find('[').unwrap() + 1..t.find(']').unwrap()];
                    let v: Vec<String> = inside
                        .split(',')
                        .map(|x| format!("{:e}", x.trim().parse::<f64>().unwrap() * g))
                        .collect();
                    format!("{key} = [{}]", v.join(", "))
                } else if key == "radius" {
                    let x: f64 = t.split('=').nth(1).unwrap().trim().parse().unwrap();
                    format!("radius = {:e}", x * f)
                } else {
                    line.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let render = |f: f64| {
        let scene = write(dir.path(), &format!("s{f:e}.toml"), &scaled(f));
        let out = dir.path().join(format!("s{f:e}.png"));
        let mut cmd = bin();
        cmd.args(["render", "--method", "direct", "--size", "24x24"])
            .args(["--photons", "5000", "--scene"])
            .arg(&scene)
            .arg("--out")
            .arg(&out);
        (cmd, out)
    };
    let (mut c, unit) = render(1.0);
    c.assert().success();
    let unit = image::open(unit).unwrap().to_rgb8();
    for f in [1e-6, 1e-4, 1e6, 1e12] {
        let (mut c, out) = render(f);
        c.assert().success();
        let img = image::open(out).unwrap().to_rgb8();
        let worst = img
            .pixels()
            .zip(unit.pixels())
            .flat_map(|(a, b)| (0..3).map(move |i| a[i].abs_diff(b[i])))
            .max()
            .unwrap();
        assert!(worst <= 3, "scale {f:e}: a pixel differs by {worst}");
    }
    let (mut c, _) = render(1e30);
    let e = c.assert().code(2);
    let stderr = String::from_utf8_lossy(&e.get_output().stderr).to_string();
    assert!(
        stderr.contains(":6: camera position") && stderr.contains("scale the scene down"),
        "{stderr}"
    );
    let (mut c, _) = render(1e-30);
    let e = c.assert().code(2);
    let stderr = String::from_utf8_lossy(&e.get_output().stderr).to_string();
    assert!(stderr.contains("scale the scene up"), "{stderr}");
}
