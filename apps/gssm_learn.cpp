// gssm-learn: learns a dataset's noise from its own log (docs/DESIGN.md
// §10) and writes the learnt scenario.ini, learn.json and the
// log-likelihood figure.
#include <algorithm>
#include <iostream>
#include <thread>

#include "cli.h"
#include "gssm/io/learn_config.h"
#include "plot_library.h"

int main(int argc, char** argv) {
  return gssm::apps::runApp("gssm-learn", [&] {
    gssm::apps::CommandLine cli("gssm-learn",
                                "Learns the noise σs a dataset's model declares learnable from the log alone "
                                "(maximum likelihood, no truth) and writes OUTDIR/scenario.ini (the input with the "
                                "learnt values), learn.json and fig-learn-loglik.png.");
    cli.option("data", "DIR", "dataset folder");
    cli.option("out", "OUTDIR", "output folder (not the dataset's)");
    cli.option("config", "FILE", "INI file to use instead of DIR/scenario.ini ([learn] gives the options)");
    cli.option("start", "SIGMA", "every σ starts here (overrides [learn] start; 0: the [model] values)");
    cli.option("threads", "N", "filter passes run at once (default: one per core)");
    cli.parse(argc, argv);
    gssm::apps::PlotLibrary plot;  // loads while the noise is learnt
    const std::string data = cli.require("data"), out = cli.require("out");
    gssm::NoiseLearningOptions options = gssm::io::learnSettings(gssm::io::readScenario(data, cli.get("config"))).options;
    if (cli.given("start")) options.start = cli.getDouble("start", 0, 1e12);
    options.threads = cli.given("threads") ? static_cast<int>(cli.getInt("threads", 1, 256))
                                           : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    options.batch.threads = options.threads;
    const gssm::io::LearnResult r = gssm::io::learnDataset(data, out, cli.get("config"), options);
    std::cout << r.report.toString();
    if (r.batch_report) std::cout << "the batch's own noise ([batch.*]):\n" << r.batch_report->toString();
    const std::string label = r.config.getString("scenario", "name", data);
    std::cout << "figure: " << plot.functions().write_learning_figure(r.report, out, label) << "\n";
    for (const auto& f : r.files) std::cout << "gssm-learn: wrote " << f << "\n";
    return r.report.converged && (!r.batch_report || r.batch_report->converged) ? 0 : 4;
  });
}
