//! Prints the calibration table: `cargo run -p hil-kinova-mujoco --example calibrate -- 30`
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let trials = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    let r = hil_kinova_mujoco::calibrate(trials, 1)?;
    let mut food = String::new();
    for row in &r.rows {
        if row.food != food {
            food = row.food.clone();
            print!("\n{food:>11}");
        }
        print!(
            "  {}={:.2}({:.2})",
            row.action,
            row.rate,
            row.published.unwrap_or(f64::NAN)
        );
    }
    println!(
        "\nMAE {:.3}  attempts/s {:.1}  overhead {:.3}",
        r.mean_abs_error, r.attempts_per_second, r.overhead_share
    );
    Ok(())
}
