//! Bit-string genomes and their decoding through a [`GenomeLayout`].

use serde::{Deserialize, Serialize};

use crate::program::{Gene, GenomeLayout};

/// A genome: one byte (0 or 1) per bit. Genomes are a few hundred bits, so
/// clarity wins over packing.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Genome {
    pub bits: Vec<u8>,
}

impl Genome {
    pub fn zeros(len: usize) -> Genome {
        Genome { bits: vec![0; len] }
    }

    /// The integer value of a gene (most significant bit first).
    pub fn gene_int(&self, gene: &Gene) -> u32 {
        let start = gene.offset as usize;
        self.bits[start..start + gene.bits as usize].iter().fold(0u32, |acc, &b| (acc << 1) | (b as u32 & 1))
    }

    /// The decoded value of a gene in its declared range.
    pub fn decode(&self, gene: &Gene) -> f32 {
        decode_int(gene, self.gene_int(gene))
    }

    /// Decodes every gene of a layout.
    pub fn decode_all(&self, layout: &GenomeLayout) -> Vec<f32> {
        layout.genes.iter().map(|g| self.decode(g)).collect()
    }

    /// Writes the integer value `v` into a gene.
    pub fn set_gene_int(&mut self, gene: &Gene, v: u32) {
        let n = gene.bits as usize;
        let start = gene.offset as usize;
        for i in 0..n {
            self.bits[start + i] = ((v >> (n - 1 - i)) & 1) as u8;
        }
    }

    /// Writes the nearest encodable value to `x` into a gene (Lamarckian write-back).
    pub fn encode(&mut self, gene: &Gene, x: f32) {
        let max = gene_max(gene);
        let u = if gene.hi == gene.lo { 0.0 } else { (x - gene.lo) / (gene.hi - gene.lo) };
        let v = (u.clamp(0.0, 1.0) * max as f32).round() as u32;
        self.set_gene_int(gene, v);
    }

    /// Renders the genome as a string of `0` and `1`.
    pub fn to_bitstring(&self) -> String {
        self.bits.iter().map(|&b| if b != 0 { '1' } else { '0' }).collect()
    }

    /// Parses a string of `0` and `1` (whitespace and `_` ignored).
    pub fn from_bitstring(s: &str) -> Option<Genome> {
        Genome::parse_bitstring(s).ok()
    }

    /// Parses a string of `0` and `1` (whitespace and `_` ignored); the
    /// error is the first other character and its position (1-based, in
    /// characters).
    pub fn parse_bitstring(s: &str) -> Result<Genome, (usize, char)> {
        let mut bits = Vec::with_capacity(s.len());
        for (i, c) in s.chars().enumerate() {
            match c {
                '0' => bits.push(0),
                '1' => bits.push(1),
                '_' | ' ' | '\n' | '\r' | '\t' => {}
                _ => return Err((i + 1, c)),
            }
        }
        Ok(Genome { bits })
    }
}

fn gene_max(gene: &Gene) -> u32 {
    if gene.bits >= 32 {
        u32::MAX
    } else {
        (1u32 << gene.bits) - 1
    }
}

/// Maps a gene's integer value to its range: `lo + (hi - lo) * g / (2^bits - 1)`.
pub fn decode_int(gene: &Gene, g: u32) -> f32 {
    let u = g as f32 / gene_max(gene) as f32;
    gene.lo + (gene.hi - gene.lo) * u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::GeneRole;

    fn gene(offset: u32, bits: u8) -> Gene {
        Gene { offset, bits, lo: -1.0, hi: 1.0, stage: 0, module: 0, role: GeneRole::Bias, frozen: false }
    }

    #[test]
    fn four_bit_genes_decode_to_sixteen_levels() {
        let g = gene(0, 4);
        let mut genome = Genome::zeros(8);
        genome.set_gene_int(&g, 15);
        assert_eq!(genome.decode(&g), 1.0);
        genome.set_gene_int(&g, 0);
        assert_eq!(genome.decode(&g), -1.0);
        genome.encode(&g, 0.0667);
        assert_eq!(genome.gene_int(&g), 8);
        assert_eq!(Genome::from_bitstring(&genome.to_bitstring()), Some(genome));
    }
}
