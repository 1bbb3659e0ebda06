// PDB and mmCIF structures read as plane points, against the files' own text: the atoms of the
// first model (the first alternative conformation of each), each coordinate the double strtod
// reads from the file's decimal, in the chosen plane and slab; gzip-compressed files alike.
// Skipped without GALPHA_WITH_GEMMI, where the refusal is tested.
#include "core/io/molecule_points.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using ::testing::HasSubstr;
using testing::IsOk;
using testing::StatusIs;

// Model 1: N, CA, C (altloc A; B is dropped), a water O; model 2 is not read.
const char kPdb[] =
    "HEADER    TEST STRUCTURE\n"
    "MODEL        1\n"
    "ATOM      1  N   ALA A   1      11.104   6.134  -6.504  1.00  0.00           N\n"
    "ATOM      2  CA  ALA A   1      11.639   6.071  -5.147  1.00  0.00           C\n"
    "ATOM      3  C  AALA A   1      13.149   5.872  -5.180  0.50  0.00           C\n"
    "ATOM      4  C  BALA A   1      13.249   5.972  -5.280  0.50  0.00           C\n"
    "HETATM    5  O   HOH A 101       1.000   2.000   3.300  1.00  0.00           O\n"
    "ENDMDL\n"
    "MODEL        2\n"
    "ATOM      1  N   ALA A   1      21.104   6.134  -6.504  1.00  0.00           N\n"
    "ENDMDL\n"
    "END\n";

// The same first model's atoms as mmCIF.
const char kCif[] =
    "data_TEST\n"
    "loop_\n"
    "_atom_site.group_PDB\n_atom_site.id\n_atom_site.type_symbol\n_atom_site.label_atom_id\n"
    "_atom_site.label_alt_id\n_atom_site.label_comp_id\n_atom_site.label_asym_id\n_atom_site.label_entity_id\n"
    "_atom_site.label_seq_id\n_atom_site.pdbx_PDB_ins_code\n_atom_site.Cartn_x\n_atom_site.Cartn_y\n"
    "_atom_site.Cartn_z\n_atom_site.occupancy\n_atom_site.B_iso_or_equiv\n_atom_site.pdbx_formal_charge\n"
    "_atom_site.auth_seq_id\n_atom_site.auth_comp_id\n_atom_site.auth_asym_id\n_atom_site.auth_atom_id\n"
    "_atom_site.pdbx_PDB_model_num\n"
    "ATOM 1 N N . ALA A 1 1 ? 11.104 6.134 -6.504 1.00 0.00 ? 1 ALA A N 1\n"
    "ATOM 2 C CA . ALA A 1 1 ? 11.639 6.071 -5.147 1.00 0.00 ? 1 ALA A CA 1\n"
    "ATOM 3 C C A ALA A 1 1 ? 13.149 5.872 -5.180 0.50 0.00 ? 1 ALA A C 1\n"
    "ATOM 4 C C B ALA A 1 1 ? 13.249 5.972 -5.280 0.50 0.00 ? 1 ALA A C 1\n"
    "HETATM 5 O O . HOH B 2 . ? 1.000 2.000 3.300 1.00 0.00 ? 101 HOH A O 1\n"
    "ATOM 6 N N . ALA A 1 1 ? 21.104 6.134 -6.504 1.00 0.00 ? 1 ALA A N 2\n";

struct Xyz {
  const char *x, *y, *z;
};
const Xyz kFirstModel[] = {{"11.104", "6.134", "-6.504"},
                           {"11.639", "6.071", "-5.147"},
                           {"13.149", "5.872", "-5.180"},
                           {"1.000", "2.000", "3.300"}};

std::string Write(const std::string& name, const std::string& text) {
  std::string path = std::filesystem::temp_directory_path() / absl::StrCat("molecule_test_", getpid(), "_", name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

#ifdef GALPHA_WITH_GEMMI

std::string WriteGz(const std::string& name, const std::string& text) {
  std::string path = std::filesystem::temp_directory_path() / absl::StrCat("molecule_test_", getpid(), "_", name);
  gzFile out = gzopen(path.c_str(), "wb");
  gzwrite(out, text.data(), static_cast<unsigned>(text.size()));
  gzclose(out);
  return path;
}

void ExpectAtoms(const absl::StatusOr<GeoreferencedPoints>& read, int u, int v) {
  ASSERT_THAT(read, IsOk());
  EXPECT_FALSE(read->crs.has_value());
  ASSERT_EQ(read->points.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const char* text[3] = {kFirstModel[i].x, kFirstModel[i].y, kFirstModel[i].z};
    EXPECT_EQ(read->points[i].x, std::strtod(text[u], nullptr)) << i;
    EXPECT_EQ(read->points[i].y, std::strtod(text[v], nullptr)) << i;
  }
}

TEST(MoleculePointsTest, PdbAndMmcifGiveTheFirstModelsAtoms) {
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"a.pdb", kPdb}, {"a.cif", kCif}}) {
    SCOPED_TRACE(name);
    const std::string path = Write(name, text);
    ExpectAtoms(ReadMoleculePoints(path, MoleculeSection{}), 0, 1);
    ExpectAtoms(ReadMoleculePoints(path, MoleculeSection{"yz", std::nullopt}), 1, 2);
    ExpectAtoms(ReadMoleculePoints(path, MoleculeSection{"zx", std::nullopt}), 2, 0);
    std::filesystem::remove(path);
    const std::string gz = WriteGz(name + ".gz", text);
    ExpectAtoms(ReadMoleculePoints(gz, MoleculeSection{}), 0, 1);
    std::filesystem::remove(gz);
  }
}

TEST(MoleculePointsTest, SlabsKeepTheAtomsBetweenTheirBounds) {
  const std::string path = Write("slab.pdb", kPdb);
  // z in [-5.2, -5.147]: the CA (z -5.147, on the bound) and the C (-5.18).
  absl::StatusOr<GeoreferencedPoints> read =
      ReadMoleculePoints(path, MoleculeSection{"xy", std::make_pair(-5.2, -5.147)});
  ASSERT_THAT(read, IsOk());
  ASSERT_EQ(read->points.size(), 2u);
  EXPECT_EQ(read->points[0].x, 11.639);
  EXPECT_EQ(read->points[1].x, 13.149);
  EXPECT_THAT(ReadMoleculePoints(path, MoleculeSection{}, 3),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("more than 3 atoms")));
  std::filesystem::remove(path);
}

// Each kept atom's radius is its element's van der Waals radius in gemmi's table, as the double of
// the table's decimal (not the float widened), and NaN for an element gemmi does not know.
TEST(MoleculePointsTest, RadiiAreTheElementsVanDerWaalsRadii) {
  const std::string path = Write("radii.pdb",
                                 "ATOM      1  N   MET A   1       0.000   0.000   0.000  1.00  0.00           N\n"
                                 "ATOM      2  CA  MET A   1       1.000   0.000   0.000  1.00  0.00           C\n"
                                 "ATOM      3  SD  MET A   1       2.000   0.000   0.000  1.00  0.00           S\n"
                                 "HETATM    4  O   HOH A 101       3.000   0.000   0.000  1.00  0.00           O\n"
                                 "HETATM    5  X1  UNK A 102       4.000   0.000   0.000  1.00  0.00           X\n"
                                 "END\n");
  std::vector<double> radii;
  absl::StatusOr<GeoreferencedPoints> read = ReadMoleculePoints(path, MoleculeSection{}, 100, &radii);
  ASSERT_THAT(read, IsOk());
  ASSERT_EQ(radii.size(), 5u);
  EXPECT_EQ(radii[0], 1.55);
  EXPECT_EQ(radii[1], 1.70);
  EXPECT_EQ(radii[2], 1.80);
  EXPECT_EQ(radii[3], 1.52);
  EXPECT_TRUE(std::isnan(radii[4]));
  EXPECT_TRUE(read->weights.empty()) << "radii are not weights: the caller makes weights of them";
  // A section keeps the radii of the atoms it keeps.
  ASSERT_THAT(ReadMoleculePoints(path, MoleculeSection{"yz", std::make_pair(1.5, 3.5)}, 100, &radii), IsOk());
  EXPECT_EQ(radii, (std::vector<double>{1.80, 1.52}));
  std::filesystem::remove(path);
}

TEST(MoleculePointsTest, WhatIsNotAStructureIsRefused) {
  const std::string path = Write("not.pdb", "this is not a structure\n");
  EXPECT_THAT(ReadMoleculePoints(path, MoleculeSection{}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("has no atoms")));
  std::filesystem::remove(path);
  EXPECT_THAT(ReadMoleculePoints("/nonexistent/x.cif", MoleculeSection{}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("cannot be read by gemmi")));
}

#else

TEST(MoleculePointsTest, RefusedWithoutGemmi) {
  const std::string path = Write("a.pdb", kPdb);
  EXPECT_THAT(ReadMoleculePoints(path, MoleculeSection{}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("GALPHA_WITH_GEMMI")));
  std::filesystem::remove(path);
}

#endif

TEST(MoleculePointsTest, PlaneAndSlabOptionsAreParsed) {
  const std::string yz = "yz", slab = "-1.5:2", bad_plane = "xz", reversed = "3:1", open = "1:";
  absl::StatusOr<MoleculeSection> section = ParseMoleculeSection(&yz, &slab);
  ASSERT_THAT(section, IsOk());
  EXPECT_EQ(section->plane, "yz");
  ASSERT_TRUE(section->slab.has_value());
  EXPECT_EQ(section->slab->first, -1.5);
  EXPECT_EQ(section->slab->second, 2.0);
  EXPECT_THAT(ParseMoleculeSection(&bad_plane, nullptr),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("--plane 'xz' is not xy, yz or zx")));
  EXPECT_THAT(ParseMoleculeSection(nullptr, &reversed),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("--slab '3:1'")));
  EXPECT_THAT(ParseMoleculeSection(nullptr, &open), StatusIs(absl::StatusCode::kInvalidArgument));
}

}  // namespace
}  // namespace galpha
