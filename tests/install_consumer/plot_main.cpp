// gssm::plot from an installed gssm: a figure drawn offscreen to a PNG.
#include <gssm/plot/figure.h>

#include <fstream>
#include <iostream>

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  gssm::plot::Figure f;
  f.title = "consumer";
  f.series.push_back({"line", {0, 1, 2}, {0, 1, 4}, gssm::plot::paletteColor(0), 2, false});
  gssm::plot::savePng(f, argv[1]);
  std::ifstream png(argv[1], std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  std::cout << "plot_consumer: wrote " << argv[1] << "\n";
  return magic[1] == 'P' && magic[2] == 'N' && magic[3] == 'G' ? 0 : 1;
}
