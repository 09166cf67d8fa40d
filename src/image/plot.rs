//! Convergence plots (relMSE against time, log-log) as SVG and PNG.
pub fn convergence_plot(_: &[(String, Vec<(f64, f64)>)], _: &str, _: &std::path::Path, _: &std::path::Path) -> anyhow::Result<()> { anyhow::bail!("todo") }
