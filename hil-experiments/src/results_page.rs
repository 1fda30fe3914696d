//! Results pages: a command's own report kept as a Markdown file (e.g.
//! `docs/results/kinova-user-study.md`), so that a figure a README cites
//! is written by the command that measured it, never typed by hand.

use std::path::Path;

use hil_core::Result;

/// A results page: the report text of one command run, with the command
/// line that wrote it.
///
/// ```
/// let page = hil_experiments::results_page::ResultsPage {
///     title: "Example",
///     command: "hil demo kinova --seeds 2",
///     report: "LinUCB r_task_avg 0.400 ± 0.020\n",
/// };
/// let md = page.to_markdown();
/// assert!(md.starts_with("<!-- Written by `hil demo kinova --seeds 2`"));
/// assert!(md.contains("```text\nLinUCB r_task_avg 0.400 ± 0.020\n```"));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ResultsPage<'a> {
    /// The page's heading.
    pub title: &'a str,
    /// The command line that produced the report (rerun it to refresh).
    pub command: &'a str,
    /// The report exactly as the command printed it.
    pub report: &'a str,
}

impl ResultsPage<'_> {
    /// The page as Markdown: a marker that the file is generated, the
    /// heading, the command, and the report verbatim in a text block.
    pub fn to_markdown(&self) -> String {
        format!(
            "<!-- Written by `{command}`: do not edit by hand, rerun the command. -->\n\
             # {title}\n\n\
             Written by the command below; rerun it to refresh this page.\n\n\
             ```sh\n{command}\n```\n\n\
             ```text\n{report}{newline}```\n",
            command = self.command,
            title = self.title,
            report = self.report,
            newline = if self.report.ends_with('\n') {
                ""
            } else {
                "\n"
            },
        )
    }

    /// Writes the page to `path`, creating its folder if needed.
    pub fn write(&self, path: &Path) -> Result<()> {
        hil_core::files::write_text(path, &self.to_markdown())
    }
}
