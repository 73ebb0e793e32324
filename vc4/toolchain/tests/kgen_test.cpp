// SPDX-License-Identifier: MIT
// The generated tables match the assembler, and every generated word disassembles and
// decodes back to itself.
#include <gtest/gtest.h>

#include <iterator>
#include <span>
#include <string>

#include "isa/disasm.hpp"
#include "isa/instr.hpp"
#include "samples/samples.hpp"
#include "vc4_kernels.hpp"

using namespace frappe::vc4;

TEST(Kgen, TablesMatchTheAssembler)
{
	const auto sum = samples::vectorSum();
	EXPECT_EQ(std::vector<uint64_t>(std::begin(generated::vector_sum_code), std::end(generated::vector_sum_code)),
	          sum.code);
	EXPECT_EQ(std::string(generated::vector_sum_uniforms[0].name), "a");
	EXPECT_EQ(std::string(generated::texture_fetch_uniforms[2].kind), "TextureConfig");
	EXPECT_EQ(std::size(generated::tile_copy_code), samples::tileCopy().code.size());
}

TEST(Kgen, GeneratedWordsRoundTrip)
{
	const std::span<const uint64_t> all[] = {generated::vector_sum_code, generated::lane_reduction_code,
	                                         generated::tile_copy_code, generated::texture_fetch_code,
	                                         generated::semaphore_gather_code};
	for (auto code : all)
		for (uint64_t w : code) {
			EXPECT_EQ(isa::encode(isa::decode(w)), w);
			EXPECT_EQ(isa::disassemble(w).find('?'), std::string::npos) << isa::disassemble(w);
		}
}
