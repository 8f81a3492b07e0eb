//! Progress bars of long offline work. indicatif draws on stderr only when
//! it is a terminal, so redirected output stays clean.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `total` items named `unit` ("steps", "commands"), with the
/// elapsed time, the rate and the time left.
pub fn bar(total: u64, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit}, {{per_sec}}, {{eta}} left"
        ))
        .expect("a valid template")
        .progress_chars("=> "),
    );
    bar
}
