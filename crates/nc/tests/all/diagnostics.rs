use kinpost_nc::Dialect;

fn err(src: &str) -> kinpost_nc::Diagnostic {
    let e = Dialect::from_toml(src, "my.toml").unwrap_err();
    assert_eq!(e.0.len(), 1, "{e}");
    e.0[0].clone()
}

#[test]
fn unknown_key_has_exact_line_and_column() {
    let d = err("name = \"x\"\nextension = \"nc\"\n\n[linear]\ndecimals = 3\n  prefx = \"X\"\n");
    assert_eq!(
        (d.file.as_str(), d.line, d.column),
        ("my.toml", 6, 3),
        "{d}"
    );
    assert!(d.message.contains("prefx"), "{d}");
    assert_eq!(d.source_line, "  prefx = \"X\"");
}

#[test]
fn unknown_top_level_table() {
    let d = err("name = \"x\"\nextension = \"nc\"\n[blok]\n");
    assert_eq!((d.line, d.column), (3, 2), "{d}");
}

#[test]
fn bad_values() {
    let d = err("name = \"x\"\nextension = \"nc\"\n[rotary]\ntrailing_zeros = \"some\"\n");
    assert_eq!((d.line, d.column), (4, 18), "{d}");
    let d = err("name = \"x\"\nextension = \"nc\"\n[axis.A]\ndecimals = 12\n");
    assert_eq!((d.line, d.column), (4, 12), "{d}");
    assert!(d.message.contains("decimals"));
    let d = err("name = \"x\"\nextension = \"nc\"\n[axis.A]\nmodulo = -360.0\n");
    assert_eq!((d.line, d.column), (4, 10), "{d}");
    let d = err("name = \"x\"\nextension = \".nc\"\n");
    assert_eq!((d.line, d.column), (2, 13), "{d}");
    let d = err("name = \"x\"\nextension = \"nc\"\n[linear]\ndecimals = \"3\"\n");
    assert_eq!(d.line, 4, "{d}");
    let d = err("extension = \"nc\"\n");
    assert!(d.message.contains("name"), "{d}");
    let d = err(
        "name = \"x\"\nextension = \"nc\"\n[axis.A]\nprefix = \"AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA\"\n",
    );
    assert_eq!((d.line, d.column), (4, 10), "{d}");
    let d = err("name = \"x\"\nextension = \"nc\"\n[axis.A]\ndecimals = 2\nmodulo = 0.001\n");
    assert_eq!((d.line, d.column), (5, 10), "{d}");
}

#[test]
fn template_syntax_error_points_into_the_file() {
    let src = "name = \"x\"\nextension = \"nc\"\n[templates]\nheader = '''\n; {{ program_name }}\nG01 {% if x %}\n'''\n";
    let d = err(src);
    assert_eq!(d.line, 6, "{d}");
    assert!(d.column >= 5, "{d}");
    assert!(d.message.contains("header"), "{d}");
    let src = "name = \"x\"\nextension = \"nc\"\n[templates]\nfooter = \"M30 {{ x \"\n";
    let d = err(src);
    assert_eq!(d.line, 4, "{d}");
    assert!(d.column > 10, "{d}");
}

#[test]
fn outside_tcp_names_command_templates_only() {
    let d = err(
        "name = \"x\"\nextension = \"nc\"\n[templates]\noutside_tcp = [\"spindle_on\", \"header\"]\n",
    );
    assert_eq!((d.line, d.column), (4, 30), "{d}");
    assert_eq!(
        d.message,
        "`templates.outside_tcp`: `header` is not a command template (one of tool_change, \
         spindle_on, spindle_off, coolant_on, coolant_off, pressure, stop, optional_stop, dwell, cutcom_on, cutcom_off)"
    );
    let d = err("name = \"x\"\nextension = \"nc\"\n[templates]\noutside_tcp = \"spindle_on\"\n");
    assert_eq!(d.line, 4, "{d}");
}

#[test]
fn rendered_diagnostic() {
    let e =
        Dialect::from_toml("name = \"x\"\nextension = \"nc\"\nbogus = 1\n", "my.toml").unwrap_err();
    let s = e.to_string();
    assert!(s.contains("--> my.toml:3:1"), "{s}");
}

#[test]
fn every_unknown_key_and_value_at_once() {
    let src = "name = \"x\"\nextension = \"nc\"\ncolour = 1\n[linear]\nprefx = \"X\"\n\
               [axis.A]\ndecimal = 3\ntrailing_zeros = \"nope\"\n[motion]\ninitial = \"g2\"\n\
               [templates]\nheadr = \"%\"\n";
    let e = Dialect::from_toml(src, "my.toml").unwrap_err();
    let got: Vec<(usize, &str)> = e.0.iter().map(|d| (d.line, d.message.as_str())).collect();
    let word = "expected one of `prefix`, `suffix`, `decimals`, `trailing_zeros`, `leading_zero`, `plus_sign`, `modulo`, `modal`";
    assert_eq!(
        got,
        [
            (
                3,
                "unknown key `colour`, expected one of `name`, `extension`, `description`, `kind`, `block`, `linear`, `rotary`, `endless`, `axis`, `pressure`, `feed`, `motion`, `arc`, `cycle`, `numbering`, `comment`, `templates`"
            ),
            (5, &format!("unknown key `prefx`, {word}")[..]),
            (7, &format!("unknown key `decimal`, {word}")[..]),
            (
                8,
                "unknown value `nope`, expected one of `keep`, `point`, `trim`"
            ),
            (
                10,
                "unknown value `g2`, expected one of `none`, `rapid`, `feed`"
            ),
            (
                12,
                "unknown key `headr`, expected one of `header`, `footer`, `tool_change`, `spindle_on`, `spindle_off`, `coolant_on`, `coolant_off`, `pressure`, `tcp_on`, `tcp_off`, `inverse_time_on`, `inverse_time_off`, `stop`, `optional_stop`, `dwell`, `cutcom_on`, `cutcom_off`, `cycle`, `cycle_off`, `outside_tcp`"
            ),
        ]
    );
}

/// Numbering values that cannot number blocks are refused at their key:
/// a wrap before the second number would give every block `N10`.
#[test]
fn numbering_that_cannot_count() {
    let head = "name = \"x\"\nextension = \"nc\"\n[numbering]\nenabled = true\n";
    for (body, line, column, key) in [
        ("wrap_after = 5\n", 5, 14, "wrap_after"),
        ("wrap_after = 10\n", 5, 14, "wrap_after"),
        (
            "start = 10\nstep = 10\nwrap_after = 19\n",
            7,
            14,
            "wrap_after",
        ),
        ("step = 0\n", 5, 8, "step"),
        ("digits = 25\n", 5, 10, "digits"),
        (
            "start = 18446744073709551615\nwrap_after = 18446744073709551615\n",
            6,
            14,
            "wrap_after",
        ),
    ] {
        let d = err(&format!("{head}{body}"));
        assert_eq!(
            (d.file.as_str(), d.line, d.column),
            ("my.toml", line, column),
            "{body}: {d}"
        );
        assert!(d.message.contains(key), "{body}: {d}");
    }
    for body in [
        "start = -1\n",
        "step = -10\n",
        "wrap_after = -1\n",
        "digits = -2\n",
    ] {
        let d = err(&format!("{head}{body}"));
        assert_eq!(
            (d.line, d.column),
            (5, body.find('-').unwrap() + 1),
            "{body}: {d}"
        );
    }
    // Two numbers before the wrap are enough.
    let d = Dialect::from_toml(
        &format!("{head}start = 10\nstep = 10\nwrap_after = 20\n"),
        "my.toml",
    );
    assert!(d.is_ok(), "{d:?}");
}

/// A template that reads a variable it is not given fails at load, at the
/// variable, whichever branch it is in; not only when a post reaches it.
#[test]
fn unknown_template_variable_is_found_at_load() {
    let head = "name = \"x\"\nextension = \"nc\"\n[templates]\n";
    let d = err(&format!(
        "{head}tool_change = \"T{{{{ tool_nmber }}}} M6\"\n"
    ));
    assert_eq!(
        (d.file.as_str(), d.line, d.column),
        ("my.toml", 4, 20),
        "{d}"
    );
    assert!(d.message.contains("template `tool_change`"), "{d}");
    assert!(d.message.contains("`tool_nmber`"), "{d}");
    assert!(d.message.contains("tool_number, cl_file"), "{d}");
    // In a branch a post may never take, and another template's variable.
    let d = err(&format!(
        "{head}footer = '''\nM30\n{{% if tool %}}\n({{{{ tool }}}} {{{{ speed }}}})\n{{% endif %}}\n'''\n"
    ));
    assert_eq!((d.line, d.column), (7, 16), "{d}");
    assert!(d.message.contains("`speed`"), "{d}");
}

/// Every documented variable, minijinja's globals and loop variables, an
/// attribute of `extra` and extras the template tests for are fine.
#[test]
fn documented_and_optional_template_variables_load() {
    let src = r#"name = "x"
extension = "nc"
[templates]
header = "{{ program_name }}{{ date }}{{ machine }}{{ tool }}{{ tool_number }}{{ cl_file }}{{ dialect }}{{ axes | join(' ') }}{{ extra.program_number }}"
footer = "{% for a in axes %}{{ loop.index }}{{ a }}{% endfor %}{{ range(2) | length }}{% if part is defined %}{{ part }}{% endif %}{% if not (op is not defined) %}{{ op }}{% endif %}{{ note | default('-') }}{{ other|d('') }}"
tool_change = "T{{ tool_number }} ({{ tool_name }})"
spindle_on = "S{{ speed | num(0) }} {{ 'M3' if clockwise else 'M4' }} {{ direction }}"
coolant_on = "{{ mode }}"
pressure = "{{ pressure_word }}={{ pressure }}"
"#;
    Dialect::from_toml(src, "my.toml").unwrap_or_else(|e| panic!("{e}"));
}

/// A `max_line_length` that cannot hold an empty comment with its line end.
#[test]
fn max_line_length_too_small() {
    let d = err("name = \"x\"\nextension = \"nc\"\n[block]\nmax_line_length = 3\n");
    assert_eq!((d.line, d.column), (4, 19), "{d}");
    assert!(d.message.contains("max_line_length"), "{d}");
    let d = Dialect::from_toml(
        "name = \"x\"\nextension = \"nc\"\n[block]\nmax_line_length = 4\n",
        "my.toml",
    )
    .unwrap();
    assert_eq!(d.block_format().max_line_length, Some(4));
}

#[test]
fn an_arc_word_the_same_both_ways_needs_two_sense_words() {
    let src = "name = \"x\"\nextension = \"nc\"\n[arc]\nclockwise = \"C\"\ncounter_clockwise = \"C\"\nplanes = [\"\", \"\", \"\"]\ncentre = [\"X\", \"Y\", \"Z\"]\nnative_planes = [\"XY\", \"XZ\"]\n";
    let e = Dialect::from_toml(src, "arc.toml").unwrap_err();
    let text = e.to_string();
    assert!(text.contains("arc.toml:4:13"), "{text}");
    assert!(text.contains("two different `sense` words"), "{text}");
    assert!(text.contains("arc.toml:8:24"), "{text}");
    assert!(text.contains("unknown plane `XZ`"), "{text}");
    let ok = src
        .replace("native_planes", "sense = [\"DR-\", \"DR+\"]\nnative_planes")
        .replace("\"XZ\"", "\"ZX\"");
    Dialect::from_toml(&ok, "arc.toml").unwrap();
}
